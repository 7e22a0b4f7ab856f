//! Discrete element method: particles (structure of arrays), contact laws, neighbour
//! search, integrator, effects, recorder and checkpoint.
