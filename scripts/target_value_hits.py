#!/usr/bin/env python3
"""How often a learner finds a kept target value (dqn/target_values.rs), by simulation.

Uniform draws of 32 slots per update from a buffer that grows by one transition a step (as
sapnet's replay does, up to its capacity), a learner that updates on a share `p` of the
steps and copies its target network every `sync` of its own steps (a copy forgets every
value). Prints the share of draws whose value was kept. BENCHMARKS.md quotes it.

    python3 scripts/target_value_hits.py
"""
import random


def hit_rate(steps, p, sync=10_000, batch=32, capacity=10**6, start=50, seed=0):
    rng = random.Random(seed)
    kept = {}
    epoch = own = hits = draws = 0
    for t in range(1, steps + 1):
        if rng.random() >= p:
            continue
        own += 1
        if own % sync == 0:
            epoch += 1
        if t < start:
            continue
        n = min(t, capacity)
        for _ in range(batch):
            slot = rng.randrange(n)
            draws += 1
            if kept.get(slot) == epoch:
                hits += 1
            else:
                kept[slot] = epoch
    return hits / draws


if __name__ == "__main__":
    for steps, p in [(22_000, 1), (22_000, 0.5), (44_000, 0.1), (44_000, 1), (700_000, 1)]:
        print(f"{steps:>8} steps, updating on {p:>4} of them: {hit_rate(steps, p):.3f}")
