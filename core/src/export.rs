//! (module export: being written)
