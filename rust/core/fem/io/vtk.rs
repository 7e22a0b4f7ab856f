//! VTK XML output: `.vtu` files (ASCII) with point and cell data, and `.pvd` collections
//! tying a time series together. Every file is written to `<name>.tmp` and renamed into
//! place, so a reader never sees a half-written file.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::error::{DemfemError, Result};

/// A named data array: `n_components` values per point (or cell), flattened.
#[derive(Debug, Clone, Copy)]
pub struct DataArray<'a> {
    /// Array name shown in ParaView.
    pub name: &'a str,
    /// Components per entry (1 scalar, 3 vector, 6 symmetric tensor as xx,yy,zz,yz,xz,xy).
    pub n_components: usize,
    /// Values, length = entries × components.
    pub values: &'a [f64],
}

fn io_err(path: &Path, e: impl std::fmt::Display) -> DemfemError {
    DemfemError::Io {
        path: path.display().to_string(),
        detail: e.to_string(),
    }
}

/// Write `contents` to `path` atomically (temp file in the same directory + rename).
pub fn write_atomic(path: &Path, contents: &str) -> Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    std::fs::write(&tmp, contents).map_err(|e| io_err(&tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| io_err(path, e))
}

fn write_array(out: &mut String, a: &DataArray<'_>, n_entries: usize) -> Result<()> {
    if a.n_components == 0 || a.values.len() != n_entries * a.n_components {
        return Err(DemfemError::ShapeMismatch {
            field: a.name.to_string(),
            detail: format!(
                "{} values for {n_entries} entries × {} components",
                a.values.len(),
                a.n_components
            ),
        });
    }
    // VTK orders symmetric tensors as XX, YY, ZZ, XY, YZ, XZ; ours are xx,yy,zz,yz,xz,xy.
    let _ = writeln!(
        out,
        r#"        <DataArray type="Float64" Name="{}" NumberOfComponents="{}" format="ascii">"#,
        a.name, a.n_components
    );
    for chunk in a.values.chunks(a.n_components) {
        out.push_str("          ");
        let reordered;
        let vals: &[f64] = if a.n_components == 6 {
            reordered = [chunk[0], chunk[1], chunk[2], chunk[5], chunk[3], chunk[4]];
            &reordered
        } else {
            chunk
        };
        for v in vals {
            let v = if v.is_finite() { *v } else { f64::NAN };
            let _ = write!(out, "{v:e} ");
        }
        out.push('\n');
    }
    out.push_str("        </DataArray>\n");
    Ok(())
}

/// Write a tetrahedral mesh with point and cell data to a `.vtu` file.
pub fn write_vtu(
    path: &Path,
    nodes: &[[f64; 3]],
    tets: &[[usize; 4]],
    point_data: &[DataArray<'_>],
    cell_data: &[DataArray<'_>],
) -> Result<()> {
    let flat: Vec<usize> = tets.iter().flatten().cloned().collect();
    write_cells(path, nodes, &flat, 4, 10, point_data, cell_data)
}

/// Write a triangle (shell mid-surface) mesh with point and cell data to a `.vtu` file.
pub fn write_vtu_triangles(
    path: &Path,
    nodes: &[[f64; 3]],
    triangles: &[[usize; 3]],
    point_data: &[DataArray<'_>],
    cell_data: &[DataArray<'_>],
) -> Result<()> {
    let flat: Vec<usize> = triangles.iter().flatten().cloned().collect();
    write_cells(path, nodes, &flat, 3, 5, point_data, cell_data)
}

fn write_cells(
    path: &Path,
    nodes: &[[f64; 3]],
    conn: &[usize],
    per_cell: usize,
    vtk_type: u8,
    point_data: &[DataArray<'_>],
    cell_data: &[DataArray<'_>],
) -> Result<()> {
    let n_cells = conn.len() / per_cell;
    let mut s = String::with_capacity(64 * nodes.len() + 64 * n_cells);
    s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n  <UnstructuredGrid>\n");
    let _ = writeln!(
        s,
        r#"    <Piece NumberOfPoints="{}" NumberOfCells="{}">"#,
        nodes.len(),
        n_cells
    );
    s.push_str("      <PointData>\n");
    for a in point_data {
        write_array(&mut s, a, nodes.len())?;
    }
    s.push_str("      </PointData>\n      <CellData>\n");
    for a in cell_data {
        write_array(&mut s, a, n_cells)?;
    }
    s.push_str("      </CellData>\n      <Points>\n        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for p in nodes {
        let _ = writeln!(s, "          {:e} {:e} {:e}", p[0], p[1], p[2]);
    }
    s.push_str("        </DataArray>\n      </Points>\n      <Cells>\n        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for c in conn.chunks_exact(per_cell) {
        if c.iter().any(|&i| i >= nodes.len()) {
            return Err(DemfemError::ShapeMismatch {
                field: "cells".into(),
                detail: "node index out of range".into(),
            });
        }
        s.push_str("         ");
        for i in c {
            let _ = write!(s, " {i}");
        }
        s.push('\n');
    }
    s.push_str("        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for i in 0..n_cells {
        let _ = writeln!(s, "          {}", per_cell * (i + 1));
    }
    s.push_str("        </DataArray>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for _ in 0..n_cells {
        let _ = writeln!(s, "          {vtk_type}");
    }
    s.push_str(
        "        </DataArray>\n      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n",
    );
    write_atomic(path, &s)
}

/// A `.pvd` collection: (time in s, file name relative to the `.pvd`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PvdSeries {
    /// Entries in time order.
    pub entries: Vec<(f64, String)>,
}

impl PvdSeries {
    /// Add one time step.
    pub fn push(&mut self, time: f64, file: impl Into<String>) {
        self.entries.push((time, file.into()));
    }

    /// Write the collection to `path` atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let mut s = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n");
        for (t, f) in &self.entries {
            let _ = writeln!(
                s,
                r#"    <DataSet timestep="{t:e}" group="" part="0" file="{f}"/>"#
            );
        }
        s.push_str("  </Collection>\n</VTKFile>\n");
        write_atomic(path, &s)
    }
}
