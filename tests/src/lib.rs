//! Helpers for the multi-process end-to-end tests.
