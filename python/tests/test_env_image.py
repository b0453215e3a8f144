"""ReactHuman-v0's ego camera image observation (``image=True``): Gymnasium's checker,
the space, bit-identical images across processes, sizes, vectorized, and the named
error without a renderer (state observations still working)."""

import hashlib
import json
import os
import subprocess
import sys
import warnings
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import reacthuman as rh
from reacthuman.env import ReactHumanEnv, rest_action

HERE = Path(__file__).parent


def test_check_env_with_images_without_warnings(ds68):
    from gymnasium.utils.env_checker import check_env

    env = gym.make("ReactHuman-v0", dataset=ds68, image=True)
    space = env.observation_space["image"]
    assert space.shape == (128, 128, 3) and space.dtype == np.uint8
    assert (space.low == 0).all() and (space.high == 255).all()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped)
    assert [str(w.message) for w in caught] == []
    obs, _ = env.reset(seed=1)
    assert env.observation_space.contains(obs)
    img = obs["image"]
    assert img.shape == (128, 128, 3) and img.dtype == np.uint8
    # A lit room, not a blank or saturated target: many distinct colours, mid brightness.
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 50
    assert 20 < img.mean() < 235
    # The state parts are those of an environment without images (drawing is read-only).
    plain = ReactHumanEnv(ds68)
    p_obs, _ = plain.reset(seed=1)
    assert info_scene(env) == plain.scene_id
    np.testing.assert_array_equal(p_obs["robot"], obs["robot"])
    np.testing.assert_array_equal(p_obs["hazard"], obs["hazard"])


def info_scene(env):
    return env.unwrapped.scene_id


def test_the_view_follows_the_body(ds68):
    """Turning in place turns the camera: the image changes a lot; the first image is
    the scene at Δ (the same for two resets of the same scene)."""
    env = ReactHumanEnv(ds68, image=True)
    sid = rh.Dataset(ds68).scene_ids[0]
    first, _ = env.reset(options={"scene_id": sid})
    again, _ = env.reset(options={"scene_id": sid})
    np.testing.assert_array_equal(first["image"], again["image"])
    turn = rest_action(env)
    turn[2] = 1.0  # full yaw rate
    obs = again
    for _ in range(6):
        obs, _, term, trunc, _ = env.step(turn)
        if term or trunc:
            break
    assert abs(obs["robot"][2]) > 0.2  # it turned
    changed = np.abs(obs["image"].astype(int) - first["image"].astype(int)).max(axis=2) > 16
    assert changed.mean() > 0.2, changed.mean()


def image_rollout(ds, seed, n=12, width=128, height=128):
    env = ReactHumanEnv(ds, image=True, image_width=width, image_height=height)
    rng = np.random.default_rng(seed)
    obs, info = env.reset(seed=seed)
    h = hashlib.sha256(obs["image"].tobytes())
    for _ in range(n):
        obs, r, term, trunc, info = env.step(rng.uniform(-1.0, 1.0, 10))
        h.update(obs["image"].tobytes() + obs["robot"].tobytes() + np.float64(r).tobytes())
        if term or trunc:
            break
    return info["scene_id"], h.hexdigest()


def test_images_are_bit_identical_in_this_and_another_process(ds68):
    a = image_rollout(ds68, 7)
    assert a == image_rollout(ds68, 7)
    assert image_rollout(ds68, 8) != a
    code = (
        "import sys, json; sys.path.insert(0, %r); import test_env_image as t; "
        "print(json.dumps(t.image_rollout(%r, 7)))" % (str(HERE), ds68)
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert tuple(json.loads(out.stdout)) == a


def test_image_size_and_bad_sizes(ds68):
    env = ReactHumanEnv(ds68, image=True, image_width=96, image_height=64)
    obs, _ = env.reset(seed=0)
    assert obs["image"].shape == (64, 96, 3)
    assert env.observation_space.contains(obs)
    for kw, match in [
        ({"image_width": 0}, "image width"),
        ({"image_height": 5000}, "image height"),
        ({"image_width": 12.5}, "image_width"),
        ({"image_height": True}, "image_height"),
    ]:
        with pytest.raises(ValueError, match=match):
            ReactHumanEnv(ds68, image=True, **kw)


def test_make_vec_with_images(ds68):
    envs = gym.make_vec(
        "ReactHuman-v0", num_envs=2, vectorization_mode="sync", dataset=ds68, image=True,
        image_width=32, image_height=24,
    )
    obs, _ = envs.reset(seed=4)
    assert obs["image"].shape == (2, 24, 32, 3) and obs["image"].dtype == np.uint8
    obs, *_ = envs.step(np.zeros((2, 10)))
    assert obs["image"].shape == (2, 24, 32, 3)
    envs.close()


NO_ADAPTER = """
import sys, numpy as np, reacthuman as rh
from reacthuman.env import ReactHumanEnv
try:
    ReactHumanEnv(sys.argv[1], image=True)
except rh.RendererUnavailableError as e:
    print("refused:", e)
else:
    print("no error"); sys.exit(3)
env = ReactHumanEnv(sys.argv[1])
obs, _ = env.reset(seed=0)
obs, *_ = env.step(np.zeros(10))
print("state ok", sorted(obs))
"""


def test_no_renderer_is_a_named_error_and_state_observations_work(ds68):
    """No Vulkan driver (the loader pointed at none): image=True raises
    RendererUnavailableError at construction; a state-only environment still runs."""
    env = dict(os.environ, VK_ICD_FILENAMES="/nonexistent/icd.json", VK_DRIVER_FILES="/nonexistent/icd.json")
    out = subprocess.run([sys.executable, "-c", NO_ADAPTER, ds68], capture_output=True, text=True, env=env)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "refused: no renderer for the ego camera image" in out.stdout
    assert "state ok ['hazard', 'robot']" in out.stdout
    assert issubclass(rh.RendererUnavailableError, RuntimeError)
    assert rh.HAS_RENDERER is True
