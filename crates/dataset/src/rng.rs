//! Deterministic random numbers for the dataset plan.
//!
//! Every random choice of a dataset (a body's shape seed, its cut, its poses, the split
//! permutation, the frames drawn from a clip) comes from a [`SplitMix64`] stream seeded by
//! [`derive()`] from the spec's seed and the choice's coordinates, so any sample can be
//! produced alone, in any order, on any machine. SplitMix64 is written out here (not taken
//! from `rand`) so datasets stay reproducible across dependency upgrades.

/// The SplitMix64 finaliser: a bijective mix of a 64-bit word.
pub fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Streams of random choices; each gets its own seed space.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u64)]
pub enum Stream {
    /// A body's shape seed: coordinates `[body]`.
    Body = 1,
    /// A body's cut of a garment: `[garment, body]`.
    Cut = 2,
    /// The poses a body wears a garment in: `[garment, body]`.
    Poses = 3,
    /// The permutation of bodies into splits: `[]`.
    Split = 4,
    /// Random frames of a clip: `[pose source, clip]`.
    Frames = 5,
    /// A procedural pose generator's seed: `[pose source, draw]`.
    Procedural = 6,
}

/// A seed for `stream` at `coords`, from the dataset `seed`.
pub fn derive(seed: u64, stream: Stream, coords: &[u64]) -> u64 {
    let mut h = mix(seed ^ mix(stream as u64));
    for &c in coords {
        h = mix(h ^ mix(c.wrapping_add(0x51_7CC1_B727_220A)));
    }
    h
}

/// The SplitMix64 generator (Steele, Lea and Flood 2014).
#[derive(Clone, Debug)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator seeded with `seed`.
    pub fn new(seed: u64) -> Self {
        Self { state: seed }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A uniform number in [0, 1) with 53 random bits.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A uniform integer in `[0, n)` (`n > 0`), without modulo bias.
    pub fn below(&mut self, n: u64) -> u64 {
        assert!(n > 0, "below(0)");
        let zone = u64::MAX - u64::MAX % n;
        loop {
            let x = self.next_u64();
            if x < zone {
                return x % n;
            }
        }
    }

    /// Shuffles `items` in place (Fisher-Yates).
    pub fn shuffle<T>(&mut self, items: &mut [T]) {
        for i in (1..items.len()).rev() {
            let j = self.below(i as u64 + 1) as usize;
            items.swap(i, j);
        }
    }

    /// `k` distinct indices of `[0, n)` in the order drawn (a partial Fisher-Yates);
    /// `k <= n`.
    pub fn choose(&mut self, n: usize, k: usize) -> Vec<usize> {
        assert!(k <= n, "choose {k} of {n}");
        let mut all: Vec<usize> = (0..n).collect();
        for i in 0..k {
            let j = i + self.below((n - i) as u64) as usize;
            all.swap(i, j);
        }
        all.truncate(k);
        all
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_first_values_and_independent_streams() {
        // Reference values of SplitMix64 seeded with 0 (Vigna's splitmix64.c).
        let mut r = SplitMix64::new(0);
        assert_eq!(r.next_u64(), 0xE220_A839_7B1D_CDAF);
        assert_eq!(r.next_u64(), 0x6E78_9E6A_A1B9_65F4);
        let a = derive(7, Stream::Body, &[3]);
        assert_eq!(a, derive(7, Stream::Body, &[3]));
        assert_ne!(a, derive(7, Stream::Cut, &[3]));
        assert_ne!(a, derive(7, Stream::Body, &[4]));
        assert_ne!(a, derive(8, Stream::Body, &[3]));
        assert_ne!(
            derive(7, Stream::Poses, &[1, 2]),
            derive(7, Stream::Poses, &[2, 1])
        );
    }

    #[test]
    fn choices_are_distinct_and_uniform() {
        let mut r = SplitMix64::new(42);
        let c = r.choose(10, 10);
        let mut sorted = c.clone();
        sorted.sort();
        assert_eq!(sorted, (0..10).collect::<Vec<_>>());
        let mut counts = [0u32; 4];
        for _ in 0..40_000 {
            counts[r.below(4) as usize] += 1;
        }
        assert!(
            counts.iter().all(|&c| (9_500..10_500).contains(&c)),
            "{counts:?}"
        );
        let mean: f64 = (0..10_000).map(|_| r.unit()).sum::<f64>() / 10_000.0;
        assert!((mean - 0.5).abs() < 0.01);
    }
}
