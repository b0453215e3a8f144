"""The inspect_ai task (integrations/inspect_ai) against rh-score: offline, with inspect's
mock model and a local stand-in for an OpenAI-compatible server that `rh-score predict`
talks to. Same prompts (hash and messages), same scores on the same answers."""

import hashlib
import importlib.util
import json
import subprocess
import sys
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import pytest

from conftest import REPO, run

spec = importlib.util.spec_from_file_location(
    "reacthuman_task", REPO / "integrations" / "inspect_ai" / "reacthuman_task.py"
)
rt = importlib.util.module_from_spec(spec)
spec.loader.exec_module(rt)

from inspect_ai import eval as inspect_eval  # noqa: E402
from inspect_ai.log import read_eval_log  # noqa: E402
from inspect_ai.model import ModelOutput, ModelUsage, get_model  # noqa: E402

# inspect's CLI takes the task file relative to its working directory (the checkout).
TASK = "integrations/inspect_ai/reacthuman_task.py"
OFFLINE = Path(__file__).resolve().parent / "inspect_offline.py"
LIMIT = 16
METRICS = {
    "saa": lambda m: m["overall"]["saa"],
    "safety": lambda m: m["overall"]["safety"],
    "balanced_accuracy": lambda m: m["balanced_accuracy"],
    "aia": lambda m: m["overall"]["aia"],
}


def hash_of(messages) -> str:
    text = json.dumps(messages, sort_keys=True, separators=(",", ":"), ensure_ascii=False)
    return hashlib.sha256(text.encode()).hexdigest()


class FakeOpenAI:
    """A local OpenAI-compatible chat endpoint: answers `answer(prompt_hash)` and keeps
    the messages it received, by their hash."""

    def __init__(self, answer):
        self.received = {}
        outer = self

        class H(BaseHTTPRequestHandler):
            def do_POST(self):
                body = json.loads(self.rfile.read(int(self.headers["Content-Length"])))
                h = hash_of(body["messages"])
                outer.received[h] = body["messages"]
                reply = {"choices": [{"index": 0, "finish_reason": "stop",
                                      "message": {"role": "assistant", "content": answer(h)}}],
                         "usage": {"prompt_tokens": 10, "completion_tokens": 5}}
                data = json.dumps(reply).encode()
                self.send_response(200)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(data)))
                self.end_headers()
                self.wfile.write(data)

            def log_message(self, *a):
                pass

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), H)
        self.thread = threading.Thread(target=self.server.serve_forever, daemon=True)

    def __enter__(self):
        self.thread.start()
        return f"http://127.0.0.1:{self.server.server_address[1]}/v1"

    def __exit__(self, *exc):
        self.server.shutdown()


def predict_via(ds: str, out: Path, answer) -> tuple[list[dict], dict]:
    """`rh-score predict --limit LIMIT` against the fake server: its lines and the messages
    the server received."""
    fake = FakeOpenAI(answer)
    with fake as url:
        run("rh-score", "predict", "--dataset", ds, "--model", "mockllm/model", "--limit", str(LIMIT),
            "--base-url", url, "--no-cache", "--quiet", "--out", str(out))
    return [json.loads(x) for x in out.read_text().splitlines()], fake.received


def lines_of(path: Path) -> list[dict]:
    return [json.loads(x) for x in path.read_text().splitlines() if x.strip()]


def rh_score_json(preds: Path, ds: str) -> dict:
    return json.loads(run("rh-score", str(preds), "--dataset", ds, "--subset", "eval", "--json", "-"))


def decisions_by_scene(preds: Path, ds: str, out: Path) -> dict:
    run("rh-score", str(preds), "--dataset", ds, "--subset", "eval", "--decisions", str(out), "--quiet")
    keep = ("status", "gt_action", "action", "saa", "rules", "first_rule", "aia", "d_end")
    return {d["scene_id"]: {k: d.get(k) for k in keep} for d in lines_of(out)}


def assert_metrics_equal(log, report: dict):
    (m,) = report["models"]
    got = {k: v.value for k, v in log.results.scores[0].metrics.items()}
    assert set(got) == set(METRICS), got
    for name, pick in METRICS.items():
        assert got[name] == pytest.approx(pick(m), abs=1e-12), name


@pytest.fixture(scope="session")
def answers(rendered) -> dict:
    """Plans for the first LIMIT eval scenes, by prompt hash: the oracle's (right), the
    freeze baseline's and always-catch's (often wrong), and text with no plan (R1)."""
    import reacthuman as rh

    ds = rh.Dataset(rendered)
    ids = ds.predict_scenes("eval", LIMIT)
    assert len(ids) == LIMIT, f"the rendered fixture needs {LIMIT} valid eval scenes"
    plans = {}
    for b in ("oracle", "freeze", "always-catch"):
        text = run("rh-score", "baseline", b, "--dataset", rendered)
        plans[b] = {x["scene_id"]: x["plan"] for x in map(json.loads, text.splitlines())}
    out = {}
    for i, sid in enumerate(ids):
        kind = ("oracle", "freeze", "always-catch", None)[i % 4]
        text = "I would rather not move." if kind is None else "Plan:\n" + json.dumps(plans[kind][sid])
        out[rh.prompt(ds, sid)["prompt_hash"]] = text
    return out


def test_inspect_cli_mockllm_hashes_equal_predict(rendered, tmp_path):
    """The acceptance command, with the mock model's default answer (not a plan)."""
    preds = tmp_path / "preds.jsonl"
    logs = tmp_path / "logs"
    r = subprocess.run(
        [sys.executable, str(OFFLINE), "eval", TASK, "--model", "mockllm/model", "--limit", str(LIMIT),
         "-T", f"dataset={rendered}", "-T", f"preds={preds}", "--log-dir", str(logs), "--display", "none"],
        capture_output=True, text=True, cwd=REPO,
    )
    assert r.returncode == 0, r.stdout + r.stderr
    (log_file,) = list(logs.glob("*.eval"))
    log = read_eval_log(str(log_file), resolve_attachments=True)
    assert log.status == "success" and len(log.samples) == LIMIT
    mine = lines_of(preds)
    assert len(mine) == LIMIT and all(x["response"] == "Default output from mockllm/model" for x in mine)
    # The same scenes and prompt hashes as rh-score predict, and the messages predict sent
    # are the samples' messages.
    theirs, received = predict_via(rendered, tmp_path / "predict.jsonl", lambda h: "no plan")
    assert {x["scene_id"]: x["prompt_hash"] for x in mine} == {x["scene_id"]: x["prompt_hash"] for x in theirs}
    for s in log.samples:
        assert rt.openai_messages(s.input) == received[s.metadata["prompt_hash"]], s.id
    dry = json.loads(run("rh-score", "predict", "--dataset", rendered, "--model", "m", "--limit", "1", "--dry-run"))
    first = next(x for x in mine if x["scene_id"] == dry["scene_id"])
    assert first["prompt_hash"] == dry["prompt_hash"] and first["prompt_version"] == dry["prompt_version"]
    # Not a plan: R1 everywhere; the log's metrics are rh-score's on the written file.
    assert all(s.scores["reacthuman"].answer == "R1" for s in log.samples)
    assert_metrics_equal(log, rh_score_json(preds, rendered))
    # The log converts to the same predictions.
    again = tmp_path / "from_log.jsonl"
    assert rt.preds_from_log(str(log_file), str(again)) == LIMIT
    key = lambda x: x["scene_id"]  # noqa: E731
    assert sorted(lines_of(again), key=key) == sorted(mine, key=key)


def test_inspect_scores_equal_rh_score_on_the_same_answers(rendered, answers, tmp_path):
    def answer(messages, tools, tool_choice, config):
        text = answers[hash_of(rt.openai_messages(messages))]
        out = ModelOutput.from_content(model="mockllm/model", content=text)
        # The fake server's usage (and no tiktoken download for the mock's count).
        out.usage = ModelUsage(input_tokens=10, output_tokens=5, total_tokens=15)
        return out

    preds = tmp_path / "preds.jsonl"
    task = rt.reacthuman(dataset=rendered, limit=LIMIT, preds=str(preds))
    (log,) = inspect_eval(task, model=get_model("mockllm/model", custom_outputs=answer),
                          log_dir=str(tmp_path / "logs"), display="none")
    assert log.status == "success" and len(log.samples) == LIMIT
    report = rh_score_json(preds, rendered)
    assert_metrics_equal(log, report)
    saa = report["models"][0]["overall"]["saa"]
    assert 0 < saa < 1, "the answers mix right and wrong plans"
    # Per sample: the grade is rh-score's decision for that scene.
    mine = decisions_by_scene(preds, rendered, tmp_path / "d_inspect.jsonl")
    for s in log.samples:
        sc = s.scores["reacthuman"]
        d = mine[s.id]
        assert sc.value == (1.0 if d["saa"] else 0.0) and sc.answer == (d["action"] or "R1"), s.id
    assert {d["action"] for d in mine.values()} >= {None, "CATCH"}
    # The same answers through rh-score predict: the same grades and the same report.
    theirs_file = tmp_path / "predict.jsonl"
    predict_via(rendered, theirs_file, lambda h: answers[h])
    assert decisions_by_scene(theirs_file, rendered, tmp_path / "d_predict.jsonl") == mine
    theirs = rh_score_json(theirs_file, rendered)["models"][0]
    for name, pick in METRICS.items():
        assert pick(theirs) == pytest.approx(pick(report["models"][0]), abs=1e-12), name


def test_task_refuses_bad_arguments(rendered, tmp_path):
    used = tmp_path / "used.jsonl"
    used.write_text('{"scene_id": "x"}\n')
    with pytest.raises(ValueError, match="already holds predictions"):
        rt.reacthuman(dataset=rendered, limit=1, preds=str(used))
    with pytest.raises(ValueError, match="subset"):
        rt.reacthuman(dataset=rendered, subset="most")
    with pytest.raises(FileNotFoundError):
        rt.reacthuman(dataset=str(tmp_path / "nope"))
