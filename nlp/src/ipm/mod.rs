//! Interior-point method (IPOPT algorithm).
