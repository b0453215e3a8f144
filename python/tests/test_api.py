"""The package's API against the binaries: the same numbers, named exceptions."""

import json
import threading
import time

import pytest

import reacthuman as rh

from conftest import run


def test_dataset_views(ds68):
    ds = rh.Dataset(ds68)
    assert len(ds) == 68
    t = ds.table()
    assert t.num_rows == 68 and "gt_action" in t.column_names
    rows = ds.scenes()
    assert [r["scene_id"] for r in rows] == ds.scene_ids
    sid = ds.scene_ids[3]
    assert ds.scene(sid)["scene_id"] == sid
    spec = ds.spec(sid)
    assert spec["scene_id"] == sid
    ev = ds.eval_ids
    assert ev is not None and 0 < len(ev) <= 68 and set(ev) <= set(ds.scene_ids)
    assert ds.table("eval").num_rows == len(ev)
    # A --no-render build has no frames; the paths are still the layout's.
    assert ds.frames(sid) == []
    paths = ds.frames(sid, existing_only=False)
    assert len(paths) == 15 and paths[0]["path"].endswith(f"frames/{sid}/ego_t0.000.png")


@pytest.mark.parametrize("subset", [None, "all"])
def test_score_equals_rh_score_json(ds68, preds, subset):
    args = [preds, "--dataset", ds68, "--json", "-"]
    if subset:
        args += ["--subset", subset]
    want = json.loads(run("rh-score", *args))
    got = rh.score(preds, ds68, subset=subset)
    assert got == want
    assert got["models"], "the report has models"


def test_score_list_of_dicts_equals_file(ds68, preds):
    lines = [json.loads(x) for x in open(preds)]
    got = rh.score(lines, rh.Dataset(ds68))
    want = json.loads(run("rh-score", preds, "--dataset", ds68, "--json", "-"))
    assert got["input"]["file"] == "<list>"
    got["input"]["file"] = want["input"]["file"]
    assert got == want


def test_decisions_equal_rh_score_decisions(ds68, preds, tmp_path):
    out = tmp_path / "decisions.jsonl"
    run("rh-score", preds, "--dataset", ds68, "--decisions", str(out), "--quiet")
    want = [json.loads(x) for x in out.read_text().splitlines()]
    # rh-score scores the evaluation subset (label rule v5: at most one NO_ACTION per family).
    n = len({d["scene_id"] for d in want})
    assert 40 <= n <= 68 and len(want) == 5 * n
    assert any(d["saa"] for d in want) and not all(d["saa"] for d in want)
    assert rh.decisions(preds, ds68) == want
    assert rh.decisions([json.loads(x) for x in open(preds)], rh.Dataset(ds68)) == want
    with pytest.raises(FileNotFoundError, match="predictions"):
        rh.decisions(tmp_path / "missing.jsonl", ds68)


def test_predict_scenes_are_predicts_selection(ds68):
    ds = rh.Dataset(ds68)
    valid = [r["scene_id"] for r in ds.scenes() if r["valid"]]
    assert ds.predict_scenes("all") == valid
    ev = set(ds.eval_ids)
    assert ds.predict_scenes("eval") == [s for s in valid if s in ev]
    assert ds.predict_scenes("eval", 3) == ds.predict_scenes("eval")[:3]
    with pytest.raises(ValueError, match="subset"):
        ds.predict_scenes("most")
    import tomllib

    from conftest import REPO

    with open(REPO / "configs" / "predict.toml", "rb") as f:
        assert rh.generation() == tomllib.load(f)["generation"]


def test_classify_equals_the_scorers_action(ds68, executed, oracle_preds):
    ds = rh.Dataset(ds68)
    for p in oracle_preds:
        c = rh.classify(p["plan"], ds, p["scene_id"])
        assert c["action"] == executed[p["scene_id"]]["action"], p["scene_id"]
    # Without a scene: the rule alone (no hazard direction).
    catch = {"walking_cmd": [0, 0, 0], "walking_duration": 0,
             "keyframes": [{"t": 0.5, "left_hand": [0.45, 0.15, 0.1], "right_hand": [0.45, -0.15, 0.1], "knee_bend": 0}]}
    c = rh.classify(catch)
    assert c["action"] == "CATCH" and c["reach"] == pytest.approx(0.35)
    assert c["hazard_dir"] is None
    walk = {"walking_cmd": [-1.0, 0, 0], "walking_duration": 1.0, "keyframes": []}
    assert rh.classify(walk)["action"] == "DODGE"
    assert rh.classify('Sure! {"walking_cmd": [0,0,0], "walking_duration": 0, "keyframes": []}')["action"] == "NO_ACTION"


def test_execute_equals_rh_score_execute(ds68, executed, oracle_preds):
    ds = rh.Dataset(ds68)
    kinds = set()
    for p in oracle_preds:
        got = rh.execute(ds, p["scene_id"], p["plan"])
        assert got == executed[p["scene_id"]]["execution"], p["scene_id"]
        kinds.add(got["outcome"])
    assert "caught" in kinds and "clear" in kinds


def test_prompt_hash_equals_predict_dry_run(rendered):
    ds = rh.Dataset(rendered)
    dry = json.loads(run("rh-score", "predict", "--dataset", rendered, "--model", "m", "--subset", "all",
                         "--limit", "1", "--dry-run"))
    p = rh.prompt(ds, dry["scene_id"])
    assert p["prompt_hash"] == dry["prompt_hash"]
    assert p["prompt_version"] == dry["prompt_version"]
    m = p["messages"]
    assert [x["role"] for x in m] == ["system", "user"]
    images = [c for c in m[1]["content"] if c["type"] == "image_url"]
    assert images and images[0]["image_url"]["url"].startswith("data:image/jpeg;base64,")
    # The elided body of --dry-run is these messages with the images elided.
    assert dry["body"]["messages"][0] == m[0]


def test_named_exceptions(ds68, tmp_path):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        rh.Dataset(tmp_path / "nope")
    with pytest.raises(FileNotFoundError, match="data/"):
        rh.Dataset(tmp_path)
    ds = rh.Dataset(ds68)
    sid = ds.scene_ids[0]
    good = {"walking_cmd": [0, 0, 0], "walking_duration": 0, "keyframes": []}
    with pytest.raises(KeyError, match="no-such-scene"):
        rh.execute(ds, "no-such-scene", good)
    with pytest.raises(KeyError):
        rh.classify(good, ds, "no-such-scene")
    with pytest.raises(KeyError):
        ds.spec("no-such-scene")
    with pytest.raises(ValueError, match="walking_cmd"):
        rh.execute(ds, sid, {"walking_cmd": "fast", "walking_duration": 1, "keyframes": []})
    with pytest.raises(ValueError, match="absurd_number"):
        rh.classify({"walking_cmd": [float("nan"), 0, 0], "walking_duration": 1, "keyframes": []})
    with pytest.raises(ValueError, match="not a plan"):
        rh.classify({"hello": 1})
    with pytest.raises(ValueError, match="plan must be a dict"):
        rh.classify(42)
    with pytest.raises(FileNotFoundError, match="predictions"):
        rh.score(tmp_path / "missing.jsonl", ds)
    with pytest.raises(ValueError, match="preds\\[1\\]"):
        rh.score([{"scene_id": sid, "model": "m", "plan": good}, 3], ds)
    with pytest.raises(ValueError, match="subset"):
        rh.score([], ds, subset="most")
    # No frames in a --no-render build.
    with pytest.raises(FileNotFoundError, match="missing observation frame"):
        rh.prompt(ds, sid)


def test_a_spec_that_does_not_replay_is_refused(ds68, tmp_path):
    import shutil

    d = tmp_path / "ds"
    shutil.copytree(ds68, d)
    ds = rh.Dataset(d)
    sid = ds.scene_ids[0]
    spec = json.loads(open(ds.spec_path(sid)).read())
    spec["bodies"][spec["hazard"]]["mass"] *= 1.5
    open(ds.spec_path(sid), "w").write(json.dumps(spec))
    with pytest.raises(ValueError, match="state hash"):
        rh.execute(ds, sid, {"walking_cmd": [0, 0, 0], "walking_duration": 0, "keyframes": []})


def test_the_gil_is_released_during_long_calls(ds68, preds, tmp_path):
    # One long native call: scoring 100 copies of the predictions (one model each).
    big = tmp_path / "big.jsonl"
    lines = open(preds).read().splitlines()
    with open(big, "w") as f:
        for i in range(100):
            for line in lines:
                x = json.loads(line)
                x["model"] = f"{x['model']}-{i}"
                f.write(json.dumps(x) + "\n")
    ds = rh.Dataset(ds68)
    stamps = []
    stop = threading.Event()

    def spin():
        i = 0
        while not stop.is_set():
            i += 1
            if i % 100 == 0:
                stamps.append(time.perf_counter())

    t = threading.Thread(target=spin)
    t.start()
    try:
        time.sleep(0.02)
        t0 = time.perf_counter()
        report = rh.score(str(big), ds)
        elapsed = time.perf_counter() - t0
    finally:
        stop.set()
        t.join()
    assert len(report["models"]) == 500
    # Holding the GIL, the call would leave the spinning thread no bytecode to run until it
    # returns: it ran in the middle of the call.
    middle = [s for s in stamps if t0 + 0.25 * elapsed < s < t0 + 0.75 * elapsed]
    assert elapsed > 0.01 and middle, (elapsed, len(stamps))


def test_a_rust_panic_is_a_runtime_error():
    from reacthuman import _native

    with pytest.raises(RuntimeError, match="deliberate panic"):
        _native._panic_for_tests()
    # The interpreter and the module still work.
    assert rh.classify({"walking_cmd": [0, 0, 0], "walking_duration": 0, "keyframes": []})["action"] == "NO_ACTION"
