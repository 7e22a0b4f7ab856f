//! File output. [`vtk`]: ASCII XML `.vtu` unstructured grids and `.pvd` time series for
//! ParaView, written atomically (temporary file, then rename).

pub mod vtk;
