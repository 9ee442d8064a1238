//! Stance sequences: data model, file format, human-like source and post-processing (Algorithm 1).
