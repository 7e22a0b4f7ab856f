//! What the CPU offers the kernels, decided once per run.

/// Whether the kernels may use their AVX2 builds: the CPU has AVX2 and `DEMFEM_NO_AVX2` is
/// unset (the variable forces the baseline builds, e.g. to compare the two). The DEM step
/// and the FEM tet forces both ask here.
pub fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::env::var_os("DEMFEM_NO_AVX2").is_none() && std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
