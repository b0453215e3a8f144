"""Environment steps per second of ReactHuman-v0: state observations, single and
vectorized (Gymnasium's SyncVectorEnv: one process, one core), and with the ego camera
image (``image=True``, single).

    python python/benches/env_steps.py DATASET [--steps N] [--num-envs K] [--control-hz HZ]
        [--image-steps N] [--image-size WxH ...]

Reports steps per CPU-second of this process (user + sys of all its threads,
`time.process_time`; with images that includes lavapipe's rasterizer threads), which is
steps per second per core, and the wall-clock rate; a wall rate below the CPU rate means
the core was shared (or, with images, that lavapipe ran on several cores). Random actions
from the action box; episodes reset on a random scene when they end (resets are counted
in the time, not as steps). The load average (1, 5, 15 min) is printed before and after.
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


def single(dataset, control_hz, seed, **kw):
    env = gym.make("ReactHuman-v0", dataset=dataset, control_hz=control_hz, **kw)
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
    ap.add_argument("--image-steps", type=int, default=600, help="steps with images (0: skip)")
    ap.add_argument("--image-size", nargs="*", default=["128x128"], help="image sizes WxH")
    a = ap.parse_args()
    print(f"ReactHuman-v0 bench: {a.steps} steps at {a.control_hz:g} Hz control, {load()}")
    fn = single(a.dataset, a.control_hz, 1)
    fn(200)  # warm-up: replays cached per scene
    cpu_rate, wall_rate, c = measure(fn, a.steps)
    print(f"single      : {cpu_rate:8.0f} steps per CPU-second ({c:.2f} CPU-s), {wall_rate:8.0f} steps/s wall")
    fn = vector(a.dataset, a.control_hz, 2, a.num_envs)
    fn(200)
    n = a.steps // a.num_envs * a.num_envs
    cpu_rate, wall_rate, c = measure(fn, n)
    print(f"vector x{a.num_envs:<3}: {cpu_rate:8.0f} steps per CPU-second ({c:.2f} CPU-s), {wall_rate:8.0f} steps/s wall")
    for size in a.image_size if a.image_steps > 0 else []:
        w, h = (int(x) for x in size.lower().split("x"))
        fn = single(a.dataset, a.control_hz, 3, image=True, image_width=w, image_height=h)
        fn(50)
        cpu_rate, wall_rate, c = measure(fn, a.image_steps)
        print(f"image {size:>7}: {cpu_rate:8.0f} steps per CPU-second ({c:.2f} CPU-s), {wall_rate:8.0f} steps/s wall")
    print(f"after: {load()}")


def load():
    return "load average %.2f %.2f %.2f" % os.getloadavg()


if __name__ == "__main__":
    main()
