//! The wire contract between `walkd`, its adapters and its clients (DESIGN.md §6).
