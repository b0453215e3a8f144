"""ReactHuman from Python.

A thin layer over the benchmark's Rust crates (the scorer ``rh-score`` and the physics
``rh-physics``), so the numbers are the binaries' own:

* :class:`Dataset` — a dataset directory (or Hub id): scenes as a ``pyarrow.Table`` or
  dicts, specs, frame paths, the eval subset;
* :func:`score` — the report of ``rh-score PREDS --dataset DIR --json -``;
* :func:`decisions` — its per-decision grades (``rh-score ... --decisions FILE``);
* :func:`classify` — the action rule (CATCH / DODGE / NO_ACTION) with its kinematics;
* :func:`prompt` — the canonical OpenAI-style messages and their ``prompt_hash``
  (``rh-score predict`` records the same);
* :func:`execute` — the physics executor's outcome of a plan (``rh-score --execute``);
* ``ReactHuman-v0`` — a Gymnasium environment (registered on import; see
  :mod:`reacthuman.env`).

Bad input raises ``ValueError`` (naming the field), an unknown scene ``KeyError``, a
missing dataset or file ``FileNotFoundError``, an image observation without a renderer
``RendererUnavailableError``; a bug in the Rust code raises ``RuntimeError`` instead of
taking the interpreter down. Long calls release the GIL.
"""

from __future__ import annotations

import json
import os
from typing import Any, Iterable, Mapping, Sequence, Union

from . import _native

__all__ = [
    "Dataset",
    "score",
    "decisions",
    "classify",
    "prompt",
    "execute",
    "versions",
    "RendererUnavailableError",
    "HAS_RENDERER",
    "generation",
    "ACTION_RULE_VERSION",
    "EXECUTOR_VERSION",
    "PROMPT_VERSION",
]

ACTION_RULE_VERSION, EXECUTOR_VERSION, PROMPT_VERSION = _native.versions()

#: Raised when the ego camera image is asked for and there is no renderer: no GPU adapter
#: (no Vulkan driver, not even Mesa's lavapipe), or a wheel built without the ``render``
#: feature (then ``HAS_RENDERER`` is False). A ``RuntimeError``.
RendererUnavailableError = _native.RendererUnavailableError
#: Whether this build has the renderer built in (an adapter may still be missing).
HAS_RENDERER: bool = _native.HAS_RENDERER

PathLike = Union[str, "os.PathLike[str]"]
Plan = Union[Mapping[str, Any], str]


def versions() -> dict:
    """The versions results depend on: action rule, executor (``[execution]``), prompt."""
    return {
        "action_rule": ACTION_RULE_VERSION,
        "executor": EXECUTOR_VERSION,
        "prompt": PROMPT_VERSION,
    }


def generation() -> dict:
    """``rh-score predict``'s generation parameters (``[generation]`` of
    ``configs/predict.toml``): ``{"temperature": ..., "max_tokens": ...}``."""
    return json.loads(_native.generation_config())


def _plan_json(plan: Plan) -> str:
    if isinstance(plan, str):
        return json.dumps(plan)
    if not isinstance(plan, Mapping):
        raise ValueError(
            f"plan must be a dict (the plan object) or a str (a model's response), got {type(plan).__name__}"
        )
    try:
        return json.dumps(plan, allow_nan=True)
    except (TypeError, ValueError) as e:
        raise ValueError(f"plan is not JSON-serializable: {e}") from None


class Dataset:
    """A ReactHuman dataset: a directory built by ``rh-pipeline build`` (``data/*.parquet``,
    ``specs/``, optionally ``frames/`` and ``eval/``), or a Hugging Face Hub dataset id
    ``owner/name[@revision]`` (downloaded once into the HF cache).

    Raises ``FileNotFoundError`` when the directory does not exist or has no ``data/``, and
    ``ValueError`` for a build that did not finish (its ``build.json`` records no file
    checksums, or files it records are missing) unless ``allow_incomplete=True``.
    """

    def __init__(self, path_or_repo: PathLike, *, allow_incomplete: bool = False) -> None:
        self._native = _native.NativeDataset(
            os.fspath(path_or_repo), allow_incomplete=allow_incomplete
        )
        self.path: str = self._native.dir
        self._ids = self._native.scene_ids()
        self._index = {s: i for i, s in enumerate(self._ids)}
        self._table = None

    def __repr__(self) -> str:
        return f"reacthuman.Dataset({self.path!r}, scenes={len(self._ids)})"

    def __len__(self) -> int:
        return len(self._ids)

    def __contains__(self, scene_id: object) -> bool:
        return scene_id in self._index

    @property
    def scene_ids(self) -> list[str]:
        """Scene ids in dataset order."""
        return list(self._ids)

    def _check(self, scene_id: str) -> None:
        if scene_id not in self._index:
            raise KeyError(f"scene_id {scene_id!r} is not in the dataset")

    def table(self, subset: str = "all"):
        """The scene table as a ``pyarrow.Table`` (``data/*.parquet``, or ``eval/*.parquet``
        with ``subset="eval"``), every column of the data contract."""
        import pyarrow.parquet as pq

        if subset not in ("all", "eval"):
            raise ValueError(f'subset must be "all" or "eval", got {subset!r}')
        folder = os.path.join(self.path, "data" if subset == "all" else "eval")
        if not os.path.isdir(folder):
            raise FileNotFoundError(f"{folder}: the dataset has no {subset} table")
        files = sorted(
            os.path.join(folder, f) for f in os.listdir(folder) if f.endswith(".parquet")
        )
        if not files:
            raise FileNotFoundError(f"{folder}: no .parquet files")
        if subset == "all" and self._table is not None:
            return self._table
        import pyarrow as pa

        t = pa.concat_tables([pq.read_table(f) for f in files])
        if subset == "all":
            self._table = t
        return t

    def scenes(self, subset: str = "all") -> list[dict]:
        """The scene table's rows as dicts (column name → value)."""
        return self.table(subset).to_pylist()

    def scene(self, scene_id: str) -> dict:
        """One scene's row as a dict. ``KeyError`` for an unknown id."""
        self._check(scene_id)
        import pyarrow.compute as pc

        t = self.table()
        rows = t.filter(pc.equal(t["scene_id"], scene_id)).slice(0, 1).to_pylist()
        return rows[0]

    @property
    def eval_ids(self) -> list[str] | None:
        """Scene ids of the balanced eval subset (sorted), or None without ``eval/``."""
        return self._native.eval_ids()

    def predict_scenes(self, subset: str = "eval", limit: int | None = None) -> list[str]:
        """The scene ids ``rh-score predict --subset SUBSET [--limit N]`` runs, in its
        order: the valid scenes of the subset (``"eval"`` or ``"all"``) in dataset order.
        ``ValueError`` when there are none or the dataset has no eval subset."""
        return self._native.predict_scenes(subset, limit)

    def spec_path(self, scene_id: str) -> str:
        """Absolute path of ``specs/<scene_id>.json``."""
        return self._native.spec_path(scene_id)

    def spec(self, scene_id: str) -> dict:
        """The full, replayable scene spec (``specs/<scene_id>.json``) as a dict."""
        path = self.spec_path(scene_id)
        with open(path, encoding="utf-8") as f:
            return json.load(f)

    def frames(self, scene_id: str, existing_only: bool = True) -> list[dict]:
        """The observation frames ``frames/<id>/<cam>_t<t>.png`` as dicts
        ``{"camera", "t", "path"}`` (only files that exist unless ``existing_only=False``;
        a ``--no-render`` build has none)."""
        out = [
            {"camera": c, "t": t, "path": p} for c, t, p in self._native.frame_paths(scene_id)
        ]
        return [f for f in out if os.path.isfile(f["path"])] if existing_only else out


def _dataset(dataset: Union[Dataset, PathLike]) -> Dataset:
    return dataset if isinstance(dataset, Dataset) else Dataset(dataset)


def score(
    preds: Union[PathLike, Sequence[Mapping[str, Any]]],
    dataset: Union[Dataset, PathLike],
    *,
    subset: str | None = None,
    answered_only: bool = False,
) -> dict:
    """Scores predictions: the same report, number for number, as
    ``rh-score PREDS --dataset DIR [--subset S] [--answered-only] --json -``.

    ``preds`` is a ``preds.jsonl`` path, or a list of prediction dicts (``scene_id``,
    ``model``, ``plan`` | ``response`` [, ``error``]), scored as those JSON lines in order
    (the report's ``input.file`` is then ``"<list>"``).
    """
    ds = _dataset(dataset)
    if isinstance(preds, (str, os.PathLike)):
        text = ds._native.score(
            path=os.fspath(preds), subset=subset, answered_only=answered_only
        )
    else:
        text = ds._native.score(
            text=_jsonl(preds), subset=subset, answered_only=answered_only
        )
    return json.loads(text)


def _jsonl(preds: Sequence[Mapping[str, Any]]) -> str:
    """Prediction dicts as JSON Lines text (``ValueError`` naming a bad item)."""
    if not isinstance(preds, Iterable) or isinstance(preds, (str, bytes, Mapping)):
        raise ValueError(
            f"preds must be a path or a list of dicts, got {type(preds).__name__}"
        )
    lines = []
    for i, p in enumerate(preds):
        if not isinstance(p, Mapping):
            raise ValueError(f"preds[{i}] must be a dict, got {type(p).__name__}")
        lines.append(json.dumps(p))
    return "\n".join(lines) + "\n"


def decisions(
    preds: Union[PathLike, Sequence[Mapping[str, Any]]],
    dataset: Union[Dataset, PathLike],
    *,
    subset: str | None = None,
) -> list[dict]:
    """The per-decision grades of ``rh-score PREDS --dataset DIR [--subset S] --decisions
    FILE``: one dict per input decision, in input order, with its ``line``, ``scene_id``,
    ``model``, ``status`` (``scored`` / ``lost`` / ``duplicate``), ``gt_action``, the
    ``action`` the rule derived (``None`` for no parseable plan), ``saa``, the safety
    ``rules`` fired and ``first_rule``, and the distance metrics. Lines the scorer drops
    (outside the subset, no scene id, ...) have no entry (see :func:`score`'s warnings).
    """
    ds = _dataset(dataset)
    if isinstance(preds, (str, os.PathLike)):
        path = os.fspath(preds)
        if not os.path.isfile(path):
            raise FileNotFoundError(f"predictions file {path} does not exist")
        with open(path, encoding="utf-8", errors="replace") as f:
            text = f.read()
    else:
        text = _jsonl(preds)
    out = ds._native.decisions(text, subset=subset)
    return [json.loads(line) for line in out.splitlines() if line.strip()]


def classify(
    plan: Plan,
    dataset: Union[Dataset, PathLike, None] = None,
    scene_id: str | None = None,
) -> dict:
    """The action rule on a plan: ``{"action": "CATCH"|"DODGE"|"NO_ACTION", ...}`` with its
    kinematics (displacement, hazard direction, D·u, reach, final base, hands in the world).

    With ``dataset`` and ``scene_id`` the rule sees that scene (its observer pose and
    hazard direction: the retreat test); without them the observer stands at the origin
    and there is no hazard direction (the retreat test cannot fire). ``plan`` is a plan
    dict or a model's raw response text, parsed as the scorer parses it (a plan the scorer
    scores as R1 raises ``ValueError`` naming the field).
    """
    text = _plan_json(plan)
    if dataset is None:
        if scene_id is not None:
            raise ValueError("scene_id needs a dataset")
        return json.loads(_native.classify_plan(text))
    ds = _dataset(dataset)
    if scene_id is None:
        raise ValueError("classify with a dataset needs a scene_id")
    return json.loads(ds._native.classify(text, scene_id))


def prompt(dataset: Union[Dataset, PathLike], scene_id: str) -> dict:
    """The canonical prompt of a scene (``configs/prompt.toml``):
    ``{"messages": [...], "prompt_hash": str, "prompt_version": str}``. ``messages`` is the
    OpenAI chat ``messages`` array (frames as JPEG data URLs) byte for byte as
    ``rh-score predict`` sends it, and ``prompt_hash`` the hash it records (and
    ``predict --dry-run`` prints). Needs a rendered dataset (``frames/``):
    ``FileNotFoundError`` otherwise."""
    ds = _dataset(dataset)
    messages, h = ds._native.prompt(scene_id)
    return {"messages": json.loads(messages), "prompt_hash": h, "prompt_version": PROMPT_VERSION}


def execute(dataset: Union[Dataset, PathLike], scene_id: str, plan: Plan) -> dict:
    """Executes a plan in physics (``rh-score --execute``): the scene is replayed from its
    spec to the decision moment (checked against the stored state hash; a mismatch raises
    ``ValueError``), the humanoid carries the plan out, and the outcome comes back:
    ``{"outcome": "caught"|"missed"|"struck"|"clear", "strike": ..., "steps": ..., ...}``."""
    ds = _dataset(dataset)
    return json.loads(ds._native.execute(scene_id, _plan_json(plan)))


# Registers ReactHuman-v0 with Gymnasium (when it is installed).
try:
    from . import env as _env  # noqa: F401
except ImportError as _e:  # pragma: no cover - gymnasium missing
    if "gymnasium" not in str(_e):
        raise
