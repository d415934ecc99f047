//! Seeding: every block of fast trials and every exact trial has its own
//! generator, derived from the study seed, a stream tag, the grade and the
//! index by SplitMix64 mixing. Results therefore do not depend on how rayon
//! schedules the work.

use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use rand_xoshiro::Xoshiro256PlusPlus;

/// SplitMix64's finaliser.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

fn derive(seed: u64, stream: u64, grade: u64, index: u64) -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(mix(mix(mix(mix(seed) ^ stream) ^ grade) ^ index))
}

/// Generator of fast-path block `block` of grade `grade`: xoshiro256++,
/// whose 64-bit arithmetic makes the normal draws of a trial (a sixth of
/// the fast path's time) cheaper than with a 128-bit PCG.
pub fn block_rng(seed: u64, grade: u64, block: u64) -> Xoshiro256PlusPlus {
    Xoshiro256PlusPlus::seed_from_u64(mix(mix(mix(mix(seed) ^ 1) ^ grade) ^ block))
}

/// Generator of exact trial `trial` of grade `grade`.
pub fn trial_rng(seed: u64, grade: u64, trial: u64) -> Pcg64Mcg {
    derive(seed, 2, grade, trial)
}
