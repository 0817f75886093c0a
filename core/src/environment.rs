//! (module environment: being written)
