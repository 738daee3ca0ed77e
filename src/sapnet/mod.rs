//! SAP-Net (paper section II): categories, the policy graph, selection, activation and
//! spreading. Pure maths over plain vectors: no candle, no I/O, no threads.

mod config;

pub use config::{BaseGraph, Paths, Prototype, SapNetParams, WeightedPrototype};
