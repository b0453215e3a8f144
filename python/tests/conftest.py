"""Fixtures: the release binaries of this checkout (target/release, or $RH_BIN_DIR) build
the datasets the tests use, and give the reference numbers the package must equal."""

import json
import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("RH_BIN_DIR", REPO / "target" / "release"))
BASELINES = ("oracle", "majority", "random", "always-catch", "freeze")


def bin_path(name: str) -> str:
    p = BIN / name
    if not p.is_file():
        pytest.fail(f"{p} is missing: build the workspace first (cargo build --release --workspace --bins)")
    return str(p)


def run(name: str, *args: str) -> str:
    r = subprocess.run([bin_path(name), *args], capture_output=True, text=True)
    assert r.returncode == 0, f"{name} {' '.join(args)}: exit {r.returncode}\n{r.stderr}"
    return r.stdout


@pytest.fixture(scope="session")
def work(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("rh")


@pytest.fixture(scope="session")
def ds68(work) -> str:
    """A label-only build of 68 scenes (every family), with its eval subset."""
    out = work / "ds68"
    run("rh-pipeline", "build", "--n", "68", "--seed", "26", "--no-render", "--quiet", "--out", str(out))
    return str(out)


@pytest.fixture(scope="session")
def preds(work, ds68) -> str:
    """The quick start's predictions: the five baselines, one model each."""
    p = work / "preds.jsonl"
    with open(p, "w") as f:
        for b in BASELINES:
            f.write(run("rh-score", "baseline", b, "--dataset", ds68, "--model", b))
    return str(p)


@pytest.fixture(scope="session")
def oracle_preds(work, ds68) -> list[dict]:
    text = run("rh-score", "baseline", "oracle", "--dataset", ds68)
    return [json.loads(line) for line in text.splitlines() if line.strip()]


@pytest.fixture(scope="session")
def executed(work, ds68, oracle_preds) -> dict:
    """`rh-score --execute` on the oracle's plans: scene id → its decision line."""
    p = work / "oracle.jsonl"
    p.write_text("".join(json.dumps(x) + "\n" for x in oracle_preds))
    d = work / "oracle_decisions.jsonl"
    run("rh-score", str(p), "--dataset", ds68, "--subset", "all", "--execute", "--no-exec-cache",
        "--decisions", str(d), "--quiet")
    lines = [json.loads(line) for line in d.read_text().splitlines()]
    return {x["scene_id"]: x for x in lines}


@pytest.fixture(scope="session")
def rendered(work) -> str:
    """A small rendered build (frames/ for the canonical prompt): 24 scenes, 19 of them in
    its eval subset (label rule v5), for the inspect task's `--limit` (16) (about 250 CPU-seconds to render)."""
    out = work / "rendered"
    run("rh-pipeline", "build", "--n", "24", "--seed", "5", "--quiet", "--out", str(out))
    return str(out)
