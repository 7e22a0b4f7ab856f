//! Checkpoint / restart.
