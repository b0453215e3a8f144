"""``ReactHuman-v0``: the benchmark's scenes as a closed-loop Gymnasium task.

``reset(seed=..., options={"scene_id": ...})`` replays the scene from its spec to the
decision moment Δ (checked against the dataset's stored state hash) and stands the
humanoid there at rest. Each ``step(action)`` applies a whole-body command for one
control period (``control_hz``, 30 Hz by default: 8 physics steps at 240 Hz) through
``rh_physics::control`` — the plan executor's own body, limits (``[execution]`` of
``configs/scoring.toml``), grasp and outcome rule. The action is 10 numbers in [-1, 1] (Gymnasium's recommended normalized box), scaled to
the physical command ``center + half_range * a`` (:func:`action_scale`; values outside
[-1, 1] are scaled too, not clipped):

====  ============================================================  ==============
0–2   base twist ``vx, vy`` (m/s, body frame) and ``yaw_rate``        ±2× the limits
3–5   left palm target ``x, y, z`` (m, body frame, as a plan's)      ±1 m
6–8   right palm target                                               ±1 m
9     knee bend (0 straight … 1 deep crouch)                          0…1
====  ============================================================  ==============

The base tracks the twist's walk under the speed/acceleration limits; the hand targets
are reached at the end of the period (linearly from the previous ones) under the hand
speed limit and the arm's reach: the executor's limits bound what the body does.

Observations (a ``Dict``): ``"robot"`` (14 numbers: base x, y, yaw relative to the pose
at Δ; base vx, vy in the body frame and yaw rate; pelvis drop; left and right palm in
the body frame; seconds since Δ) and, with ``privileged=True`` (default), ``"hazard"``
(9 numbers: position relative to the base and velocity, both in the body frame; angular
velocity) and, with ``image=True``, ``"image"``: the humanoid's ego camera at the step's
end, ``image_height`` × ``image_width`` × 3 ``uint8`` RGB (128 × 128 by default), drawn by
the dataset's renderer (``rh_render::EgoCamera``: wgpu on Vulkan, Mesa's lavapipe on a
CPU) — the spec's ``ego`` camera carried by the base and the pelvis drop, the executing
body's links drawn, the dataset's lighting and shadows. Without a renderer (no Vulkan
driver, or a wheel built without the ``render`` feature) ``image=True`` raises
:class:`reacthuman.RendererUnavailableError` at construction; state observations need
none. ``render_mode`` must be None.

Reward: at the end, ``rewards[outcome]`` (``struck`` −1; ``caught`` +1 on CATCH scenes,
``caught_other`` 0 elsewhere; ``missed`` and ``clear`` 0) minus ``step_cost`` per step,
plus ``shaping(obs, action, info)`` if given. ``terminated`` when the outcome is settled
(struck, caught, or the hazard at rest on the floor after the last moving command),
``truncated`` at the executor's horizon; ``info`` has the scene id and time, and, from
``reset`` and at the end, the scene's ``labels``; at the end also ``outcome`` (the kind) and ``outcome_detail`` (the executor's outcome, flattened to
fixed types so vectorized infos stack: :func:`flat_outcome`).
"""

from __future__ import annotations

import json
from typing import Any, Callable, Mapping, Optional, Sequence

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from . import _native

ENV_ID = "ReactHuman-v0"

#: The scene columns copied into ``info["labels"]`` (those the dataset has).
LABEL_COLUMNS = (
    "scene_id",
    "family",
    "gt_action",
    "dangerous",
    "danger_present",
    "adversarial",
    "speed_band",
    "object_id",
    "valid",
)

DEFAULT_REWARDS = {
    "struck": -1.0,
    "caught": 1.0,
    "caught_other": 0.0,
    "missed": 0.0,
    "clear": 0.0,
}

_ROBOT_LEN, _HAZARD_LEN = _native.state_lengths()
# Observation bounds: wide enough for anything the physics produces in a 4 s scene
# (positions in m, speeds in m/s, angular speeds in rad/s); Gymnasium wants finite ones.
_POS, _VEL, _ANG = 1.0e3, 1.0e3, 1.0e5


def _robot_space() -> spaces.Box:
    return spaces.Box(-_VEL, _VEL, shape=(_ROBOT_LEN,), dtype=np.float64)


def _hazard_space() -> spaces.Box:
    high = np.array([_POS] * 3 + [_VEL] * 3 + [_ANG] * 3, dtype=np.float64)
    return spaces.Box(-high, high, dtype=np.float64)


def action_scale(execution: Mapping[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """``(center, half_range)`` of the physical command: an action ``a`` in [-1, 1]^10
    commands ``center + half_range * a``. Twist: ±2× the executor's base limits (the
    reference may ask for more than the body can do; the limits clip it); palms ±1 m;
    knee bend 0…1."""
    v = 2.0 * execution["max_speed"]
    w = 2.0 * execution["max_yaw_rate"]
    center = np.array([0.0] * 9 + [0.5], dtype=np.float64)
    half = np.array([v, v, w] + [1.0] * 6 + [0.5], dtype=np.float64)
    return center, half


class ReactHumanEnv(gym.Env):
    """The closed-loop ReactHuman task (see the module doc)."""

    metadata = {"render_modes": []}

    def __init__(
        self,
        dataset: Any,
        scene_ids: Optional[Sequence[str]] = None,
        subset: str = "all",
        control_hz: float = 30.0,
        privileged: bool = True,
        rewards: Optional[Mapping[str, float]] = None,
        step_cost: float = 0.0,
        shaping: Optional[Callable[[dict, np.ndarray, dict], float]] = None,
        render_mode: Optional[str] = None,
        image: bool = False,
        image_width: int = 128,
        image_height: int = 128,
    ) -> None:
        from . import Dataset

        if render_mode is not None:
            raise ValueError(
                f"render_mode {render_mode!r}: ReactHuman-v0 has no render modes (the ego camera is an observation: image=True)"
            )
        self.dataset = dataset if isinstance(dataset, Dataset) else Dataset(dataset)
        if scene_ids is None:
            if subset == "eval":
                ids = self.dataset.eval_ids
                if ids is None:
                    raise ValueError("subset='eval': the dataset has no eval/ subset")
            elif subset == "all":
                ids = self.dataset.scene_ids
            else:
                raise ValueError(f'subset must be "all" or "eval", got {subset!r}')
            valid = {r["scene_id"]: r.get("valid", True) for r in self._label_rows()}
            scene_ids = [s for s in ids if valid.get(s, True)]
        scene_ids = list(scene_ids)
        for s in scene_ids:
            if s not in self.dataset:
                raise KeyError(f"scene_id {s!r} is not in the dataset")
        if not scene_ids:
            raise ValueError("no scenes to run")
        self.scene_ids = scene_ids
        if not (isinstance(control_hz, (int, float)) and control_hz > 0):
            raise ValueError(f"control_hz must be a positive number, got {control_hz!r}")
        self.control_hz = float(control_hz)
        self.privileged = bool(privileged)
        self.rewards = dict(DEFAULT_REWARDS)
        for k, v in (rewards or {}).items():
            if k not in DEFAULT_REWARDS:
                raise ValueError(f"rewards: unknown key {k!r} (known: {sorted(DEFAULT_REWARDS)})")
            self.rewards[k] = float(v)
        self.step_cost = float(step_cost)
        self.shaping = shaping
        self.render_mode = None
        self.execution = json.loads(_native.execution_config())
        self.action_center, self.action_half_range = action_scale(self.execution)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(10,), dtype=np.float64)
        obs = {"robot": _robot_space()}
        if self.privileged:
            obs["hazard"] = _hazard_space()
        self.image = bool(image)
        self._ego: Optional[_native.NativeEgoCamera] = None
        if self.image:
            for name, v in (("image_width", image_width), ("image_height", image_height)):
                if not isinstance(v, (int, np.integer)) or isinstance(v, bool):
                    raise ValueError(f"{name} must be an int (pixels), got {v!r}")
            # RendererUnavailableError without a renderer; ValueError outside 1..=4096.
            self._ego = _native.NativeEgoCamera(int(image_width), int(image_height))
            self.image_shape = (int(image_height), int(image_width), 3)
            obs["image"] = spaces.Box(0, 255, shape=self.image_shape, dtype=np.uint8)
        self.observation_space = spaces.Dict(obs)
        self._labels = {r["scene_id"]: r for r in self._label_rows()}
        self._session: Optional[_native.NativeSession] = None
        self.scene_id: Optional[str] = None
        self.steps = 0

    def _label_rows(self) -> list[dict]:
        t = self.dataset.table()
        cols = [c for c in LABEL_COLUMNS if c in t.column_names]
        return t.select(cols).to_pylist()

    def command(self, action: np.ndarray) -> np.ndarray:
        """The physical command of a normalized action (see :func:`action_scale`)."""
        return self.action_center + self.action_half_range * np.asarray(action, dtype=np.float64)

    def action_of(self, command: np.ndarray) -> np.ndarray:
        """The normalized action of a physical command (the inverse of :meth:`command`)."""
        return (np.asarray(command, dtype=np.float64) - self.action_center) / self.action_half_range

    @property
    def period(self) -> float:
        """The control period (s) of the current episode."""
        if self._session is None:
            raise RuntimeError("call reset() first")
        return self._session.period()

    def _obs(self) -> dict:
        s = self._session
        obs = {"robot": np.asarray(s.robot_state(), dtype=np.float64)}
        if self.privileged:
            obs["hazard"] = np.asarray(s.hazard_state(), dtype=np.float64)
        if self._ego is not None:
            obs["image"] = np.frombuffer(self._ego.draw(s), dtype=np.uint8).reshape(self.image_shape)
        return obs

    def _info(self, labels: bool) -> dict:
        info = {"scene_id": self.scene_id, "t": self._session.time()}
        if labels:
            info["labels"] = dict(self._labels[self.scene_id])
        return info

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict] = None):
        super().reset(seed=seed)
        options = options or {}
        scene_id = options.get("scene_id")
        if scene_id is None:
            scene_id = self.scene_ids[int(self.np_random.integers(len(self.scene_ids)))]
        elif scene_id not in self.dataset:
            raise KeyError(f"options['scene_id'] {scene_id!r} is not in the dataset")
        self.scene_id = scene_id
        self._session = _native.NativeSession(self.dataset._native, scene_id, self.control_hz)
        self.steps = 0
        return self._obs(), self._info(labels=True)

    def step(self, action):
        if self._session is None:
            raise RuntimeError("call reset() before step()")
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        if a.shape != (10,):
            raise ValueError(f"action must have 10 numbers, got shape {np.shape(action)}")
        end = self._session.step(self.command(a).tolist())
        self.steps += 1
        obs = self._obs()
        info = self._info(labels=end is not None)
        reward = -self.step_cost
        if end is not None:
            outcome = json.loads(self._session.outcome())
            info["outcome"] = outcome["outcome"]
            info["outcome_detail"] = flat_outcome(outcome)
            kind = outcome["outcome"]
            if kind == "caught" and info["labels"].get("gt_action") != "CATCH":
                kind = "caught_other"
            reward += self.rewards[kind]
        if self.shaping is not None:
            reward += float(self.shaping(obs, a, info))
        return obs, float(reward), end == "terminated", end == "truncated", info


def flat_outcome(o: Mapping[str, Any]) -> dict:
    """The executor's outcome with fixed types, for vectorized infos (Gymnasium stacks
    each key across environments): no ``None``, no nested dict. Absent numbers are NaN,
    absent names ``""``; ``strike`` becomes ``strike_part``, ``strike_impulse``,
    ``strike_speed``, ``strike_t``."""
    nan = float("nan")
    strike = o.get("strike") or {}
    return {
        "outcome": o["outcome"],
        "strike_part": strike.get("part", ""),
        "strike_impulse": strike.get("impulse", nan),
        "strike_speed": strike.get("speed", nan),
        "strike_t": strike.get("t", nan),
        "first_contact_t": nan if o.get("first_contact_t") is None else o["first_contact_t"],
        "first_contact_part": o.get("first_contact_part") or "",
        "min_hand_distance": o["min_hand_distance"],
        "base_end": np.asarray(o["base_end"], dtype=np.float64),
        "floor_t": nan if o.get("floor_t") is None else o["floor_t"],
        "catch_attempted": bool(o["catch_attempted"]),
        "limits_hit": np.asarray(o["limits_hit"], dtype=bool),
        "steps": int(o["steps"]),
        "state_hash": o["state_hash"],
    }


class PlanPolicy:
    """The scripted policy: a plan (dict, the scorer's plan forms) carried out period by
    period — its walk while it walks, its hand targets and knee bend at each period's end
    (``rh_physics::control::plan_command``). Stepped through the environment it reaches
    the executor's outcome for the same plan (``reacthuman.execute``)."""

    def __init__(self, env: gym.Env, plan: Mapping[str, Any]) -> None:
        self.env = env.unwrapped
        self.plan = json.dumps(plan)

    def __call__(self, j: int) -> np.ndarray:
        """The action of control period ``j`` (0 at Δ)."""
        c = _native.plan_action(self.env.dataset._native, self.plan, self.env.period, j)
        return self.env.action_of(c)


def rest_action(env: gym.Env) -> np.ndarray:
    """The normalized action that stands still with the hands at rest."""
    return env.unwrapped.action_of(_native.rest_action())


def register_envs() -> None:
    """Registers ``ReactHuman-v0`` (idempotent)."""
    if ENV_ID not in gym.registry:
        gym.register(id=ENV_ID, entry_point="reacthuman.env:ReactHumanEnv")


register_envs()
