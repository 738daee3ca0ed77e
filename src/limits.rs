//! The bounds every count and duration read from a config or a folder is checked against
//! before it is used: far beyond what an experiment needs, so that a typo or a hostile
//! file is refused with its field instead of allocating, wrapping or running for ever.

/// The most training episodes a run (or a source) may ask for: 1,000 times the paper's
/// longest protocol. Each episode keeps a return in memory and a row on disk.
pub const MAX_EPISODES: u32 = 10_000_000;

/// The most greedy test episodes per run.
pub const MAX_TEST_EPISODES: u32 = 100_000;

/// The most source policies a library may hold (the paper's has 10).
pub const MAX_SOURCES: usize = 10_000;

/// The most gradient updates per round: each is a minibatch, and signals are read between
/// them.
pub const MAX_GRADIENT_STEPS: u32 = 10_000;

/// The largest minibatch.
pub const MAX_BATCH: usize = 1 << 16;

/// The most runs per method a protocol may ask for: far beyond what a comparison needs
/// (hundreds separate the closest methods), and refused before anything is planned.
pub const MAX_RUNS: u32 = 10_000;

/// The most methods a comparison of runs from elsewhere (`sapnet compare`, a compare
/// folder opened) sets side by side: every pair of them is bootstrapped, so a count a
/// file could make large would cost hours; a legend is unreadable long before.
pub const MAX_METHODS: usize = 100;

/// The most environment steps a run, an exclusion or a schedule may count: 10^12, a
/// million times the paper's longest run. Step arithmetic below it cannot overflow a u64.
pub const MAX_STEPS: u64 = 1_000_000_000_000;

/// Most hidden layers a network may have: far deeper than these tasks need, and a bound on
/// the names that results derive from a method's layers.
pub const MAX_HIDDEN_LAYERS: usize = 64;

/// The most numbers a reader keeps from one CSV file of a folder or a run (8 bytes each):
/// a return per row of `episodes.csv`, `tests.csv` or a monitor file, three per source per
/// row of `activations.csv`. 2^25: a third more than the largest protocol a folder is known
/// to hold (24 M episodes), 256 MiB of values. So a file of short rows, within its size
/// bound or decompressed from a few kilobytes, cannot make a reader keep gigabytes.
pub const MAX_VALUES_KEPT: usize = 1 << 25;
