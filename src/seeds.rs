//! Seeds derived from the one run seed, so that every run, method and environment gets its
//! own stream and the same config and seed give the same numbers.
//!
//! A stream is named by a path: the base seed, then parts, each a name or an index
//! (`seed 0 / "run" / "sapnet" / 3`). The path is encoded without ambiguity — a version tag,
//! then every part with its kind and, for a name, its length — and hashed with SHA-256, so
//! two different paths give unrelated seeds: swapping the base with a part, or two parts,
//! or moving bytes from one name to the next, changes the stream. (The derivation before
//! 2026-12 mixed base and parts symmetrically: `derive(s, [m])` was `derive(m, [s])`, so a
//! sweep over seeds shared streams crosswise between methods.)

use sha2::{Digest, Sha256};

/// One part of a stream's path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part<'a> {
    /// What the stream is for, or whose it is: `"run"`, a method's label, `"weights"`.
    Name(&'a str),
    /// Which one: a run's index, a source's.
    Index(u64),
}

/// The seed of the stream `parts` names below `base`.
pub fn derive(base: u64, parts: &[Part<'_>]) -> u64 {
    let mut hash = Sha256::new();
    hash.update(b"sapnet seed v2\0");
    hash.update(base.to_le_bytes());
    for part in parts {
        match part {
            Part::Name(name) => {
                hash.update([1]);
                hash.update((name.len() as u64).to_le_bytes());
                hash.update(name.as_bytes());
            }
            Part::Index(index) => {
                hash.update([2]);
                hash.update(index.to_le_bytes());
            }
        }
    }
    let digest = hash.finalize();
    u64::from_le_bytes(digest[..8].try_into().expect("SHA-256 has 32 bytes"))
}

/// The seed of run `run` of the method labelled `method` under the config's `seed`. A
/// method's runs depend on its label, not its place in the list: reordering a protocol,
/// or running one method alone in a sweep's cell, keeps its numbers.
pub fn run_seed(seed: u64, method: &str, run: u32) -> u64 {
    derive(
        seed,
        &[
            Part::Name("run"),
            Part::Name(method),
            Part::Index(u64::from(run)),
        ],
    )
}

/// The derivation of sapnet before 2026-12 (SplitMix64 over the parts, symmetric in base
/// and parts), kept for one use: planning a source library (its architectures and each
/// source's seed). The shipped libraries' manifests record seeds drawn with it, and a
/// library is checked against its plan when training resumes; its parts are a key no
/// experiment uses (`u64::MAX`) and the source's index, so it shares no stream with a run.
pub fn library_v1(base: u64, parts: &[u64]) -> u64 {
    parts.iter().fold(splitmix64(base), |seed, &part| {
        splitmix64(seed ^ splitmix64(part))
    })
}

fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn derivation_is_stable_and_separates_streams() {
        use Part::{Index, Name};
        assert_eq!(
            derive(7, &[Index(1), Index(2)]),
            derive(7, &[Index(1), Index(2)])
        );
        assert_ne!(
            derive(7, &[Index(1), Index(2)]),
            derive(7, &[Index(2), Index(1)])
        );
        assert_ne!(derive(7, &[Index(0)]), derive(8, &[Index(0)]));
        assert_ne!(derive(7, &[]), derive(7, &[Index(0)]));
        // The old derivation's flaw: base and part swapped gave the same stream.
        assert_eq!(library_v1(3, &[5]), library_v1(5, &[3]));
        assert_ne!(derive(3, &[Index(5)]), derive(5, &[Index(3)]));
        // Names are length-prefixed and kind-tagged: no two spellings of one path.
        assert_ne!(
            derive(0, &[Name("ab"), Name("c")]),
            derive(0, &[Name("a"), Name("bc")])
        );
        assert_ne!(derive(0, &[Name("")]), derive(0, &[Index(0)]));
    }

    /// The shipped libraries were planned with the old derivation: it must not change.
    /// `saved_policies/cartpole/source-3.ron` records `seed: 8954760860737877267`.
    #[test]
    fn the_library_derivation_is_frozen() {
        assert_eq!(library_v1(0, &[u64::MAX, 3]), 8_954_760_860_737_877_267);
    }

    proptest! {
        #[test]
        fn swapping_the_base_with_a_part_or_two_parts_changes_the_stream(
            base in any::<u64>(),
            parts in proptest::collection::vec(any::<u64>(), 1..5),
            i in any::<proptest::sample::Index>(),
            j in any::<proptest::sample::Index>(),
        ) {
            let path: Vec<Part> = parts.iter().map(|&p| Part::Index(p)).collect();
            let seed = derive(base, &path);
            let i = i.index(parts.len());
            if parts[i] != base {
                let mut swapped = parts.clone();
                swapped[i] = base;
                let swapped: Vec<Part> = swapped.iter().map(|&p| Part::Index(p)).collect();
                prop_assert_ne!(seed, derive(parts[i], &swapped));
            }
            let j = j.index(parts.len());
            if parts[i] != parts[j] {
                let mut swapped = path.clone();
                swapped.swap(i, j);
                prop_assert_ne!(seed, derive(base, &swapped));
            }
        }

        #[test]
        fn a_method_and_a_seed_swapped_are_different_runs(
            seed in 0u64..1000,
            other in 0u64..1000,
            run in 0u32..100,
        ) {
            prop_assume!(seed != other);
            // A sweep over `seed` whose methods are labelled by numbers is the worst case.
            prop_assert_ne!(
                run_seed(seed, &other.to_string(), run),
                run_seed(other, &seed.to_string(), run)
            );
        }
    }
}
