//! (module growth: being written)
