"""Environment steps per second of ReactHuman-v0 (state observations), single and
vectorized (Gymnasium's SyncVectorEnv: one process, one core).

    python python/benches/env_steps.py DATASET [--steps N] [--num-envs K] [--control-hz HZ]

Reports steps per CPU-second of this process (user + sys, `time.process_time`), which is
steps per second per core, and the wall-clock rate; a wall rate below the CPU rate means
the core was shared. Random actions from the action box; episodes reset on a random
scene when they end (resets are counted in the time, not as steps).
"""

import argparse
import os
import time

import gymnasium as gym
import numpy as np

import reacthuman  # noqa: F401  (registers ReactHuman-v0)


def measure(fn, steps):
    c0, w0 = time.process_time(), time.perf_counter()
    fn(steps)
    c, w = time.process_time() - c0, time.perf_counter() - w0
    return steps / c, steps / w, c


def single(dataset, control_hz, seed):
    env = gym.make("ReactHuman-v0", dataset=dataset, control_hz=control_hz)
    rng = np.random.default_rng(seed)
    env.reset(seed=seed)

    def run(n):
        for _ in range(n):
            _, _, term, trunc, _ = env.step(rng.uniform(-1.0, 1.0, 10))
            if term or trunc:
                env.reset()

    return run


def vector(dataset, control_hz, seed, k):
    envs = gym.make_vec("ReactHuman-v0", num_envs=k, vectorization_mode="sync",
                        dataset=dataset, control_hz=control_hz)
    rng = np.random.default_rng(seed)
    envs.reset(seed=seed)

    def run(n):
        for _ in range(n // k):
            envs.step(rng.uniform(-1.0, 1.0, (k, 10)))  # autoreset on end

    return run


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dataset")
    ap.add_argument("--steps", type=int, default=4000)
    ap.add_argument("--num-envs", type=int, default=8)
    ap.add_argument("--control-hz", type=float, default=30.0)
    a = ap.parse_args()
    print(f"ReactHuman-v0 bench: {a.steps} steps at {a.control_hz:g} Hz control, load average {os.getloadavg()[0]:.2f}")
    fn = single(a.dataset, a.control_hz, 1)
    fn(200)  # warm-up: replays cached per scene
    cpu_rate, wall_rate, c = measure(fn, a.steps)
    print(f"single      : {cpu_rate:8.0f} steps per CPU-second ({c:.2f} CPU-s), {wall_rate:8.0f} steps/s wall")
    fn = vector(a.dataset, a.control_hz, 2, a.num_envs)
    fn(200)
    n = a.steps // a.num_envs * a.num_envs
    cpu_rate, wall_rate, c = measure(fn, n)
    print(f"vector x{a.num_envs:<3}: {cpu_rate:8.0f} steps per CPU-second ({c:.2f} CPU-s), {wall_rate:8.0f} steps/s wall")


if __name__ == "__main__":
    main()
