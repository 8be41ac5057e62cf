//! symx: scalar expression graphs.
