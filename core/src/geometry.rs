//! (module geometry: being written)
