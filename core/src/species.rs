//! (module species: being written)
