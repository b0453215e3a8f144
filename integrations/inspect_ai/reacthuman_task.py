"""ReactHuman as an inspect_ai task (issue 28).

    inspect eval integrations/inspect_ai/reacthuman_task.py --model openai/gpt-4o \\
        -T dataset=DIR [-T subset=eval|all] [-T limit=N] [-T preds=preds.jsonl]

Every sample is one scene of the subset, in the order ``rh-score predict`` runs them
(valid scenes of the subset in dataset order). Its input is the canonical prompt of
``configs/prompt.toml`` — the messages ``rh-score predict`` sends, built by the same Rust
code through the ``reacthuman`` package — and its metadata carries the ``prompt_hash``
``predict`` records: the messages held by the sample are converted back to the OpenAI form
and hashed when the sample is built, and a mismatch stops the task. The generation
parameters are ``predict``'s (``configs/predict.toml``: temperature, max_tokens).

The scorer grades each answer with the benchmark's own scoring (``reacthuman.decisions``:
the scorer's plan parser, action rule, safety rules R1-R4 and distance metrics, as
``rh-score --decisions``). The metrics (``saa``, ``safety``, ``balanced_accuracy``,
``aia``) are the headline numbers of the ``rh-score`` report on the run's predictions
(``reacthuman.score``), so they equal ``rh-score preds.jsonl --dataset DIR --subset S``.

``-T preds=FILE`` appends one ``preds.jsonl`` line per answer (the format ``rh-score``
reads: scene_id, model, response, prompt_version, prompt_hash, usage); the file must not
exist or be empty. ``python reacthuman_task.py preds LOG OUT`` writes the same lines from
an inspect log afterwards (samples that failed become ``error`` lines: lost decisions).
One epoch only: several answers to one scene are duplicates to ``rh-score``.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
from concurrent.futures import ThreadPoolExecutor
from functools import lru_cache
from typing import Any

import reacthuman as rh
from inspect_ai import Task, task
from inspect_ai.dataset import MemoryDataset, Sample
from inspect_ai.model import (
    ChatMessage,
    ChatMessageSystem,
    ChatMessageUser,
    ContentImage,
    ContentText,
    GenerateConfig,
)
from inspect_ai.scorer import Metric, SampleScore, Score, Target, metric, scorer
from inspect_ai.solver import TaskState, generate

# Scene columns copied into each sample's metadata (when the dataset has them).
META_COLUMNS = ("family", "speed_band", "gt_action", "object_name", "adversarial", "dangerous")


@lru_cache(maxsize=8)
def load(dataset: str) -> rh.Dataset:
    """The dataset (loaded once per path)."""
    return rh.Dataset(dataset)


def dataset_path(dataset: str | None) -> str:
    path = dataset or os.environ.get("RH_DATASET")
    if not path:
        raise ValueError(
            "reacthuman task: give the dataset (-T dataset=DIR or owner/name) or set RH_DATASET"
        )
    return path


def inspect_messages(messages: list[dict]) -> list[ChatMessage]:
    """The canonical OpenAI ``messages`` as inspect messages (text and image parts)."""
    out: list[ChatMessage] = []
    for i, m in enumerate(messages):
        role, content = m.get("role"), m.get("content")
        if role == "system" and isinstance(content, str):
            out.append(ChatMessageSystem(content=content))
        elif role == "user" and isinstance(content, list):
            parts: list[ContentText | ContentImage] = []
            for j, c in enumerate(content):
                if c.get("type") == "text":
                    parts.append(ContentText(text=c["text"]))
                elif c.get("type") == "image_url":
                    img = c["image_url"]
                    parts.append(ContentImage(image=img["url"], detail=img.get("detail", "auto")))
                else:
                    raise ValueError(f"prompt messages[{i}].content[{j}]: unknown part type {c.get('type')!r}")
            out.append(ChatMessageUser(content=parts))
        else:
            raise ValueError(f"prompt messages[{i}]: unsupported role/content ({role!r})")
    return out


def openai_messages(messages: list[ChatMessage]) -> list[dict]:
    """Inspect messages back in the canonical OpenAI form (the inverse of
    :func:`inspect_messages`)."""
    out: list[dict] = []
    for m in messages:
        if isinstance(m.content, str):
            out.append({"role": m.role, "content": m.content})
            continue
        parts: list[dict] = []
        for c in m.content:
            if isinstance(c, ContentText):
                parts.append({"type": "text", "text": c.text})
            elif isinstance(c, ContentImage):
                parts.append({"type": "image_url", "image_url": {"url": c.image, "detail": c.detail}})
            else:
                raise ValueError(f"{m.role} message: unsupported content {type(c).__name__}")
        out.append({"role": m.role, "content": parts})
    return out


def prompt_hash(messages: list[dict]) -> str:
    """``rh-score predict``'s ``prompt_hash``: SHA-256 of the messages as compact JSON with
    sorted keys (serde_json's form of the request's ``messages``)."""
    text = json.dumps(messages, sort_keys=True, separators=(",", ":"), ensure_ascii=False)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def scene_sample(ds: rh.Dataset, scene_id: str, row: dict) -> Sample:
    """One scene as a sample: the canonical prompt, the label as target, the hash."""
    p = rh.prompt(ds, scene_id)
    messages = inspect_messages(p["messages"])
    h = prompt_hash(openai_messages(messages))
    if h != p["prompt_hash"]:
        raise RuntimeError(
            f"scene {scene_id}: the sample's messages hash to {h}, not the canonical prompt_hash {p['prompt_hash']}"
        )
    meta = {"scene_id": scene_id, "prompt_hash": h, "prompt_version": p["prompt_version"]}
    meta.update({k: row[k] for k in META_COLUMNS if k in row})
    return Sample(id=scene_id, input=messages, target=str(row.get("gt_action", "")), metadata=meta)


def samples(ds: rh.Dataset, subset: str, limit: int | None) -> list[Sample]:
    """The samples of ``predict --subset SUBSET [--limit N]``, in its order (prompts are
    built in parallel: the native call releases the GIL)."""
    ids = ds.predict_scenes(subset, limit)
    table = ds.table()
    columns = [c for c in ("scene_id", *META_COLUMNS) if c in table.column_names]
    rows = {r["scene_id"]: r for r in table.select(columns).to_pylist()}
    with ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        return list(pool.map(lambda s: scene_sample(ds, s, rows[s]), ids))


def prediction_line(state: TaskState) -> dict:
    """The answer as a ``preds.jsonl`` line (the fields ``rh-score predict`` writes)."""
    out = state.output
    usage = out.usage
    line: dict[str, Any] = {
        "scene_id": state.metadata["scene_id"],
        "model": str(state.model),
        "response": out.completion,
        "usage": {
            "prompt_tokens": usage.input_tokens if usage else 0,
            "completion_tokens": usage.output_tokens if usage else 0,
        },
        "prompt_version": state.metadata["prompt_version"],
        "prompt_hash": state.metadata["prompt_hash"],
        "error": None,
    }
    if out.stop_reason == "content_filter":
        line["refusal"] = True
    return line


def report_of(dataset: str, subset: str, scores: list[SampleScore]) -> dict | None:
    """The ``rh-score`` report's model entry for the predictions behind these scores."""
    lines = [s.score.metadata["prediction"] for s in scores if "prediction" in (s.score.metadata or {})]
    if not lines:
        return None
    try:
        report = rh.score(lines, load(dataset), subset=subset)
    except ValueError as e:  # nothing scored: the report is refused
        print(f"reacthuman: no report: {e}", file=sys.stderr)
        return None
    models = report["models"]
    if len(models) != 1:
        raise RuntimeError(f"expected one model in the run's predictions, got {[m['model'] for m in models]}")
    return models[0]


def headline(name: str, pick) -> Any:
    """A metric named ``name``: one number of the rh-score report (NaN without one)."""

    def factory(dataset: str, subset: str) -> Metric:
        def compute(scores: list[SampleScore]) -> float:
            m = report_of(dataset, subset, scores)
            v = pick(m) if m is not None else None
            return float("nan") if v is None else float(v)

        return compute

    factory.__name__ = name
    return metric(name=name, scores="unreduced")(factory)


saa = headline("saa", lambda m: m["overall"]["saa"])
safety = headline("safety", lambda m: m["overall"]["safety"])
balanced_accuracy = headline("balanced_accuracy", lambda m: m["balanced_accuracy"])
aia = headline("aia", lambda m: m["overall"]["aia"])


def explanation(d: dict) -> str:
    rules = ", ".join(d.get("rules") or []) or "none"
    action = d.get("action") or "none (no parseable plan)"
    return f"ground truth {d.get('gt_action')}; plan's action {action}; safety rules fired: {rules}"


@scorer(metrics=[], name="reacthuman")
def reacthuman_scorer(dataset: str, subset: str = "eval", preds: str | None = None):
    """Grades an answer with ``rh-score``'s scoring; value 1 when the plan's action is the
    scene's label (SAA). Metrics: the rh-score report of all answers."""
    ds = load(dataset)

    async def score(state: TaskState, target: Target) -> Score:
        line = prediction_line(state)
        graded = rh.decisions([line], ds, subset=subset)
        if len(graded) != 1:
            raise RuntimeError(f"scene {line['scene_id']}: rh-score graded {len(graded)} decisions, expected 1")
        d = graded[0]
        if preds:
            with open(preds, "a", encoding="utf-8") as f:
                f.write(json.dumps(line) + "\n")
        return Score(
            value=1.0 if d.get("saa") else 0.0,
            answer=d.get("action") or "R1",
            explanation=explanation(d),
            metadata={"prediction": line, "decision": d},
        )

    return score


@task
def reacthuman(
    dataset: str | None = None, subset: str = "eval", limit: int | None = None, preds: str | None = None
) -> Task:
    """The ReactHuman eval subset (``subset="all"``: every valid scene) with the canonical
    prompt and ``rh-score``'s scoring. ``limit``: the first N scenes (as ``predict
    --limit``; inspect's ``--limit`` also works but builds every prompt first)."""
    path = load(dataset_path(dataset)).path
    if subset not in ("eval", "all"):
        raise ValueError(f'reacthuman task: subset must be "eval" or "all", got {subset!r}')
    if preds and os.path.exists(preds) and os.path.getsize(preds) > 0:
        raise ValueError(
            f"reacthuman task: preds file {preds} already holds predictions; remove it or choose another"
        )
    gen = rh.generation()
    return Task(
        dataset=MemoryDataset(samples(load(path), subset, limit), name="reacthuman", location=path),
        solver=generate(),
        scorer=reacthuman_scorer(path, subset, preds),
        metrics=[m(path, subset) for m in (saa, safety, balanced_accuracy, aia)],
        config=GenerateConfig(temperature=gen["temperature"], max_tokens=gen["max_tokens"]),
        epochs=1,
        metadata={"dataset": path, "subset": subset, "prompt_version": rh.PROMPT_VERSION, **rh.versions()},
    )


def preds_from_log(log_file: str, out: str) -> int:
    """Writes the ``preds.jsonl`` of an inspect log of this task (atomically); returns the
    number of lines. A sample without a score (it failed) becomes an ``error`` line."""
    from inspect_ai.log import read_eval_log

    log = read_eval_log(log_file)
    lines = []
    for s in log.samples or []:
        sc = (s.scores or {}).get("reacthuman")
        if sc is not None and sc.metadata and "prediction" in sc.metadata:
            lines.append(sc.metadata["prediction"])
        else:
            meta = s.metadata or {}
            lines.append({
                "scene_id": str(s.id), "model": log.eval.model, "response": None,
                "error": s.error.message if s.error else "no answer scored",
                "prompt_version": meta.get("prompt_version"), "prompt_hash": meta.get("prompt_hash"),
            })
    tmp = f"{out}.tmp{os.getpid()}"
    with open(tmp, "w", encoding="utf-8") as f:
        f.writelines(json.dumps(x) + "\n" for x in lines)
    os.replace(tmp, out)
    return len(lines)


if __name__ == "__main__":
    if len(sys.argv) != 4 or sys.argv[1] != "preds":
        sys.exit("usage: python reacthuman_task.py preds LOG_FILE OUT_JSONL")
    n = preds_from_log(sys.argv[2], sys.argv[3])
    print(f"wrote {n} prediction lines to {sys.argv[3]}")
