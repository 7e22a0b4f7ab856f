//! The kernel entry points ([`pair_chunk`], [`wall_chunk`], [`particle_chunk`]) compiled a
//! second time for AVX2, and chosen per chunk by `avx2` (set when the CPU has it; see
//! [`cpu_has_avx2`]). The AVX2 build runs the same IEEE operations in the same order (Rust
//! never fuses a multiply and an add on its own), so results are bitwise those of the
//! baseline build; the VEX three-operand encoding drops most of the register moves SSE2
//! needs around glam's three-component vectors.

use super::batch::Batch;
use super::chunk::{pair_chunk, wall_chunk};
use super::gather::{particle_chunk, ParticleCtx};
use super::pair::{PairCtx, PairLists};
use super::state::{Flips, PairContact, WallContact, WallDetail, WallOut};
use super::wall::{BlockWalls, WallCtx};
use crate::geometry::Vec3;

/// Whether the step may use its AVX2 build ([`crate::cpu::has_avx2`]).
pub(super) fn cpu_has_avx2() -> bool {
    crate::cpu::has_avx2()
}

/// `$name(avx2, args…)` calls `$inner::<E>(args…)`, through `$avx` (the same body
/// compiled with AVX2 enabled) when `avx2` is set.
macro_rules! avx2_dispatch {
    ($name:ident, $avx:ident, $inner:ident, ($($arg:ident: $ty:ty),*) -> $ret:ty) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        #[allow(clippy::too_many_arguments)]
        fn $avx<const E: u16>($($arg: $ty),*) -> $ret {
            $inner::<E>($($arg),*)
        }

        #[inline(always)]
        #[allow(clippy::too_many_arguments)]
        pub(super) fn $name<const E: u16>(avx2: bool, $($arg: $ty),*) -> $ret {
            #[cfg(target_arch = "x86_64")]
            if avx2 {
                // SAFETY: `avx2` is true only when the CPU reported AVX2.
                return unsafe { $avx::<E>($($arg),*) };
            }
            let _ = avx2;
            $inner::<E>($($arg),*)
        }
    };
}

avx2_dispatch!(pair, pair_chunk_avx2, pair_chunk, (
    chunk: &mut [PairContact],
    lists: PairLists<'_>,
    konst: &[u32],
    flips: &mut [Flips],
    c: &PairCtx<'_>,
    batch: &mut Batch
) -> ());

avx2_dispatch!(wall, wall_chunk_avx2, wall_chunk, (
    c: &WallCtx<'_>,
    first: usize,
    lists: BlockWalls<'_>,
    slots: &mut [WallContact],
    out: &mut [WallOut],
    detail: &mut [WallDetail],
    batch: &mut Batch
) -> ());

avx2_dispatch!(particle, particle_chunk_avx2, particle_chunk, (
    c: &ParticleCtx<'_>,
    first: usize,
    position: &mut [Vec3],
    velocity: &mut [Vec3],
    omega: &mut [Vec3],
    force_sum: &mut [Vec3],
    coordination: &mut [u32],
    wall_coordination: &mut [u32],
    slots: &[WallContact],
    wall_out: &[WallOut]
) -> (f64, f64, bool, u32));
