//! What the two explicit FEM solver classes share, written once: both wrap the core's one
//! integrator ([`demfem::fem::Explicit`]), so stepping with the GIL released, contact
//! (rigid surfaces, springs, output, pressure, counters), checkpoints, the clock, nodal
//! translations and velocities, and the energies are the same methods for tets
//! ([`crate::fem_tet::FemTetSolver`]) and shells ([`crate::fem_shell::FemShellSolver`]).
//! [`explicit_solver_methods!`] writes the `#[pymethods]` block of a class from its own
//! methods and these. Times in s, lengths in m, forces in N, energies in J.
//!
//! A class using the macro has a field `inner` (the core solver) and names how the contact
//! model of its mesh is made (solid or shell) from the class `s`, the body and region of
//! every node and the settings.

/// The `#[pymethods]` block of an explicit solver class `$class`: its own methods (`$own`)
/// followed by the shared ones; `$contact` makes its contact model.
macro_rules! explicit_solver_methods {
    (
        $class:ident,
        contact($s:ident, $body:ident, $region:ident, $settings:ident) => $contact:expr,
        { $($own:tt)* }
    ) => {
        #[pymethods]
        impl $class {
            $($own)*

            /// Advance `n_steps` with the GIL released, in chunks of `chunk` steps; after
            /// each chunk `progress(steps, time_s)` is called if given, and Ctrl-C stops
            /// cleanly with SimulationInterrupted (the state stays consistent at a step
            /// boundary).
            #[pyo3(signature = (n_steps, chunk=1000, progress=None))]
            fn run(
                &mut self,
                py: Python<'_>,
                n_steps: u64,
                chunk: u64,
                progress: Option<Bound<'_, PyAny>>,
            ) -> PyResult<()> {
                $crate::run::run_in_chunks(
                    py,
                    &mut self.inner,
                    n_steps,
                    chunk,
                    |inner, k| inner.run(k),
                    |inner| (inner.time(), inner.steps()),
                    |inner| {
                        if let Some(cb) = &progress {
                            cb.call1((inner.steps(), inner.time()))?;
                        }
                        Ok(())
                    },
                )
            }

            /// Attach contact (before the first step): bodies numbered per node
            /// (`body_of_node`), output regions per node, penalty scale s (k = s·K·A²/V
            /// per face for tets, s·E·t for shells), friction μ between bodies,
            /// broad-phase margin (m), rigid surfaces as tuples ("plane", point, normal,
            /// surface_velocity, μ), ("sphere", centre, radius, velocity, μ) or
            /// ("cylinder", point, radius, axis, μ), and optional no-tension springs
            /// (nodes, anchors (m,3) m, stiffness N/m, rest length m). The stable step is
            /// re-certified with the contact included.
            #[pyo3(signature = (body_of_node, region_of_node, penalty_scale=1.0, friction=0.2, margin=None, contacts_per_node=1.0, initial_overlap_tolerance=1e-9, output_interval=10, rigid_surfaces=Vec::new(), spring_nodes=None, spring_anchors=None, spring_stiffness=None, spring_rest_length=None))]
            #[allow(clippy::too_many_arguments)]
            fn set_contact(
                &mut self,
                py: Python<'_>,
                body_of_node: PyReadonlyArray1<'_, i64>,
                region_of_node: PyReadonlyArray1<'_, i64>,
                penalty_scale: f64,
                friction: f64,
                margin: Option<f64>,
                contacts_per_node: f64,
                initial_overlap_tolerance: f64,
                output_interval: usize,
                rigid_surfaces: Vec<$crate::fem_contact::PyRigid>,
                spring_nodes: Option<PyReadonlyArray1<'_, i64>>,
                spring_anchors: Option<PyReadonlyArray2<'_, f64>>,
                spring_stiffness: Option<PyReadonlyArray1<'_, f64>>,
                spring_rest_length: Option<PyReadonlyArray1<'_, f64>>,
            ) -> PyResult<()> {
                let settings = demfem::fem::contact::ContactSettings {
                    penalty_scale,
                    friction,
                    margin,
                    contacts_per_node,
                    initial_overlap_tolerance,
                    output_interval,
                };
                let n = self.inner.mass().len();
                let body = $crate::convert::ids(&body_of_node, "body_of_node", n)?;
                let region = $crate::convert::ids(&region_of_node, "region_of_node", n)?;
                let c = {
                    let ($s, $body, $region, $settings) = (&*self, &body[..], &region[..], settings);
                    $contact
                }
                .map_err($crate::error::core_err)?;
                let c = $crate::fem_contact::add_surfaces_and_springs(
                    c,
                    rigid_surfaces,
                    spring_nodes,
                    spring_anchors,
                    spring_stiffness,
                    spring_rest_length,
                )?;
                let inner = &mut self.inner;
                py.detach(|| inner.set_contact(c))
                    .map_err($crate::error::core_err)
            }

            /// Contact output channels: list of (party a, party b, region of a), a < b
            /// (bodies first, then rigid surfaces in the order given).
            fn contact_channels(&self) -> Vec<(usize, usize, usize)> {
                self.inner
                    .contact()
                    .map(|c| c.channels())
                    .unwrap_or_default()
            }

            /// Contact history (samples, 1 + 4·channels): time s, then per channel the
            /// normal and tangential resultant force N, contact area m², largest
            /// penetration m.
            fn contact_history<'py>(&self, py: Python<'py>) -> PyResult<$crate::convert::Nodes<'py>> {
                let (h, w) = match self.inner.contact() {
                    Some(c) => (c.history().to_vec(), 1 + 4 * c.channels().len()),
                    None => (Vec::new(), 1),
                };
                let rows = h.len() / w;
                let a = numpy::ndarray::Array2::from_shape_vec((rows, w), h)
                    .map_err(|x| $crate::error::shape_err("contact history", x.to_string()))?;
                Ok(a.into_pyarray(py))
            }

            /// Contact pressure per node in the last step (normal force over the
            /// tributary area; one side's for shells), Pa (N,).
            fn contact_pressure<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
                let p = self
                    .inner
                    .contact()
                    .map(|c| c.pressure())
                    .unwrap_or_else(|| vec![0.0; self.inner.mass().len()]);
                p.into_pyarray(py)
            }

            /// Contact energies (J) and counters: elastic_energy, spring_energy,
            /// friction_work, rigid_work, contact_work, bookkeeping_error,
            /// active_contacts, broad_phase_builds, eigenvalue_allowance (1/s²),
            /// max_contact_eigenvalue (1/s²), dt_limit_without_contact (s),
            /// surface_nodes, surface_faces; None without contact.
            fn contact_info<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
                match self.inner.contact() {
                    Some(c) => Ok(Some($crate::fem_contact::info(
                        py,
                        c,
                        self.inner.dt_limit_without_contact(),
                    )?)),
                    None => Ok(None),
                }
            }

            /// Initial velocity (before the first step): (N,3) m/s of the translations, or
            /// one column per dof (shells: (N,6), the rotations in rad/s); fixed dofs
            /// must get 0.
            fn set_initial_velocity(&mut self, v: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
                let v = $crate::convert::node_dofs(&v, "velocity", self.inner.mass().len())?;
                self.inner
                    .set_initial_velocity(&v)
                    .map_err($crate::error::core_err)
            }

            /// Translational lumped mass per node (N,), kg.
            fn mass<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
                self.inner.mass().to_vec().into_pyarray(py)
            }

            /// Add the weight of the lumped masses in the acceleration `g` (m/s²) to the
            /// loads.
            fn add_gravity(&mut self, g: [f64; 3]) -> PyResult<()> {
                self.inner.add_gravity(g).map_err($crate::error::core_err)
            }

            /// The run's dynamic state (contact included) as bytes, for an exact
            /// checkpoint.
            fn save_state<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
                PyBytes::new(py, &self.inner.save_state())
            }

            /// Restore a state from :meth:`save_state` into a solver built from the same
            /// inputs; a state of another model raises ShapeError and changes nothing.
            fn restore_state(&mut self, state: &[u8]) -> PyResult<()> {
                self.inner
                    .restore_state(state)
                    .map_err($crate::error::core_err)
            }

            /// Time step in use, s.
            #[getter]
            fn dt(&self) -> f64 {
                self.inner.dt()
            }
            /// Certified stable-step bound (contact included once attached), s.
            #[getter]
            fn dt_limit(&self) -> f64 {
                self.inner.dt_limit()
            }
            /// Current time, s.
            #[getter]
            fn time(&self) -> f64 {
                self.inner.time()
            }
            /// Steps taken.
            #[getter]
            fn steps(&self) -> u64 {
                self.inner.steps()
            }

            /// Translation of each node (N,3), m.
            fn displacement<'py>(&self, py: Python<'py>) -> PyResult<$crate::convert::Nodes<'py>> {
                $crate::convert::arr3(py, &self.inner.node_displacement())
            }
            /// Translational velocity at the last half step (N,3), m/s.
            fn velocity<'py>(&self, py: Python<'py>) -> PyResult<$crate::convert::Nodes<'py>> {
                $crate::convert::arr3(py, &self.inner.node_velocity())
            }

            /// Energies (J) at the start of the last step: time (s), kinetic, internal,
            /// external_work (loads, reactions and contact), damping_work, initial, and
            /// relative_balance_error of the whole balance (contact energy, friction and
            /// rigid-surface work included).
            fn energy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                let e = self.inner.energy();
                let d = PyDict::new(py);
                d.set_item("time", e.time)?;
                d.set_item("kinetic", e.kinetic)?;
                d.set_item("internal", e.internal)?;
                d.set_item("external_work", e.external_work)?;
                d.set_item("damping_work", e.damping_work)?;
                d.set_item("initial", e.initial)?;
                d.set_item(
                    "relative_balance_error",
                    self.inner.energy_balance().relative_balance_error(),
                )?;
                Ok(d)
            }
        }
    };
}

pub(crate) use explicit_solver_methods;
