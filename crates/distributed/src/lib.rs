//! The plan of a distributed render, without any transport: how N ranks split a volume.
//!
//! Issue 15. Only the k-d decomposition has landed ([`kd`]); the ghost layers, the
//! binary-swap schedule and the MPI transport are still to come.

pub mod kd;
