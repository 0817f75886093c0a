//! (module edit: being written)
