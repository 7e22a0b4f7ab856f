//! The kernels of one block: the pairs of one block of the pair list ([`pair_chunk`]) and
//! the wall slots of one block of particles ([`wall_chunk`]), each batched
//! ([`super::batch`]) where the effects allow it and one contact at a time otherwise
//! ([`super::pair`], [`super::wall`]); both give the same bits. Forces in N, lengths in m.

use super::batch::{pair_chunk_batched, wall_chunk_batched, Batch, BATCH};
use super::pair::{pair_kernel, PairCtx, PairLists};
use super::state::{Flips, PairContact, WallContact, WallDetail, WallOut};
use super::wall::{wall_kernel, BlockWalls, WallCtx};
use super::{on, NO_WALL, PAIR_CHUNK};
use crate::dem::effects::Effect;

/// Pair kernels of one block of the pair list (starting at a multiple of `PAIR_CHUNK`); the
/// contacts begun and ended are added to `flips`, one entry per `PAIR_CHUNK` pairs.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn pair_chunk<const E: u16>(
    chunk: &mut [PairContact],
    lists: PairLists<'_>,
    konst: &[u32],
    flips: &mut [Flips],
    c: &PairCtx<'_>,
    batch: &mut Batch,
) {
    if c.batched && !on::<E>(c.effects, Effect::RollingResistance) {
        return match c.pairs_uniform {
            Some(_) if c.avx2 => {
                pair_chunk_batched::<E, true>(chunk, lists, konst, flips, c, batch)
            }
            _ => pair_chunk_batched::<E, false>(chunk, lists, konst, flips, c, batch),
        };
    }
    // one at a time: every pair is tested (its wake stays a valid bound, see
    // `Simulation::pair_wake`, as the travel keeps growing)
    let PairLists {
        active,
        onset,
        out,
        detail,
        rolling,
        ..
    } = lists;
    for (e, ((((((p, a), s), o), d), r), k)) in chunk
        .iter_mut()
        .zip(active.iter_mut())
        .zip(onset.iter_mut())
        .zip(out.iter_mut())
        .zip(detail.iter_mut())
        .zip(rolling.iter_mut())
        .zip(konst)
        .enumerate()
    {
        let f = pair_kernel::<E>(p, a, s, &c.table[*k as usize], o, d, r, c);
        if let Some(chunk_flips) = flips.get_mut(e / PAIR_CHUNK) {
            chunk_flips.onsets += f.onsets;
            chunk_flips.ends += f.ends;
        }
    }
}

/// Wall kernels of the particles of one chunk starting at `first` (their slots).
#[inline(always)]
pub(super) fn wall_chunk<const E: u16>(
    c: &WallCtx<'_>,
    first: usize,
    lists: BlockWalls<'_>,
    slots: &mut [WallContact],
    out: &mut [WallOut],
    detail: &mut [WallDetail],
    batch: &mut Batch,
) {
    let stride = c.wall_stride;
    if c.shared.batched && !on::<E>(c.shared.effects, Effect::RollingResistance) && stride <= BATCH
    {
        wall_chunk_batched::<E>(c, first, lists, slots, out, detail, batch);
        return;
    }
    for (k, ((slots, out), detail)) in slots
        .chunks_exact_mut(stride)
        .zip(out.chunks_exact_mut(stride))
        .zip(detail.chunks_exact_mut(stride))
        .enumerate()
    {
        let i = first + k;
        if !c.alive[i] {
            continue;
        }
        let (x, v, w) = (
            c.shared.position[i],
            c.shared.velocity[i],
            c.shared.omega[i],
        );
        for ((s, o), d) in slots.iter_mut().zip(out.iter_mut()).zip(detail.iter_mut()) {
            if s.wall == NO_WALL {
                break;
            }
            wall_kernel::<E>(s, o, d, i, x, v, w, c);
        }
    }
}
