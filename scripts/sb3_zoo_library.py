#!/usr/bin/env python3
"""Trains three Stable-Baselines3 DQN agents of different architectures on CartPole-v1 with
the RL Baselines3 Zoo's hyper-parameters (hyperparams/dqn.yml, as ../shared/bench/sb3_dqn.py
has them), to import into a sapnet library beside its native sources (docs/IMPORT.md).

Usage: python3 scripts/sb3_zoo_library.py --out DIR [--timesteps 50000] [--threads 1]

Writes DIR/sb3-64.zip, DIR/sb3-64x64.zip and DIR/sb3-256x256.zip (`model.save`, seeds 0, 1,
2) and prints one JSON line per agent: its architecture, seed, wall time and the mean greedy
return of 10 evaluation episodes (deterministic, a fresh env seeded seed + 1000).
Needs `pip install stable-baselines3 gymnasium`.
"""
import argparse
import json
import time
from pathlib import Path

import gymnasium as gym
import stable_baselines3
import torch
from stable_baselines3 import DQN
from stable_baselines3.common.evaluation import evaluate_policy
from stable_baselines3.common.monitor import Monitor

ZOO_CARTPOLE = dict(learning_rate=2.3e-3, batch_size=64, buffer_size=100000, learning_starts=1000,
                    gamma=0.99, target_update_interval=10, train_freq=256, gradient_steps=128,
                    exploration_fraction=0.16, exploration_final_eps=0.04)
AGENTS = [("sb3-64", [64], 0), ("sb3-64x64", [64, 64], 1), ("sb3-256x256", [256, 256], 2)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    ap.add_argument("--timesteps", type=int, default=50000)
    ap.add_argument("--threads", type=int, default=1)
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name, net_arch, seed in AGENTS:
        model = DQN("MlpPolicy", Monitor(gym.make("CartPole-v1")), policy_kwargs=dict(net_arch=net_arch),
                    seed=seed, device="cpu", verbose=0, **ZOO_CARTPOLE)
        t0 = time.perf_counter()
        model.learn(total_timesteps=args.timesteps)
        wall = time.perf_counter() - t0
        model.save(out / f"{name}.zip")
        eval_env = Monitor(gym.make("CartPole-v1"))
        eval_env.reset(seed=seed + 1000)
        mean_r, std_r = evaluate_policy(model, eval_env, n_eval_episodes=10, deterministic=True)
        print(json.dumps(dict(name=name, net_arch=net_arch, seed=seed, timesteps=args.timesteps,
                              wall_s=round(wall, 1), eval_mean=float(mean_r), eval_std=float(std_r),
                              sb3=stable_baselines3.__version__, torch=torch.__version__,
                              gymnasium=gym.__version__)), flush=True)


if __name__ == "__main__":
    main()
