//! Fuzz/property test of `rh-score`'s input handling: garbage, truncated, deeply nested,
//! numerically absurd and huge lines never panic and never stop the run — exit 0 with
//! every line accounted for (scored, lost, blank or counted as a warning).

use rh_e2e::{run, run_ok};
use serde_json::Value;
use std::io::Write;
use std::path::{Path, PathBuf};

/// xorshift64*: a tiny deterministic generator (no dependency).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("score-fuzz-{}", std::process::id()))
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn garbage_truncated_and_huge_lines_never_stop_the_run() {
    let work = scratch("fuzz");
    let ds = work.join("ds");
    rh_e2e::make_fixture(&ds, 40, 3);
    let valid = run_ok(
        "rh-score",
        &["baseline", "random", "--dataset", ds.to_str().unwrap()],
    );
    let good: Vec<&str> = valid.lines().collect();
    let ids: Vec<String> = good
        .iter()
        .map(|l| {
            serde_json::from_str::<Value>(l).unwrap()["scene_id"]
                .as_str()
                .unwrap()
                .to_string()
        })
        .collect();

    let mut rng = Rng(0x5eed_1234_abcd_0001);
    let mut lines: Vec<Vec<u8>> = Vec::new();
    for i in 0..3000 {
        let g = good[rng.below(good.len() as u64) as usize].as_bytes();
        let id = &ids[rng.below(ids.len() as u64) as usize];
        let model = format!("fuzz-{}", rng.below(4));
        let line: Vec<u8> = match rng.below(16) {
            // A valid line, possibly as a new model.
            0 => g.to_vec(),
            // Truncated at a random point.
            1 => g[..rng.below(g.len() as u64) as usize].to_vec(),
            // Random bytes (invalid UTF-8 included, newlines excluded).
            2 => (0..rng.below(300)).map(|_| (rng.below(255) as u8).max(1)).filter(|&b| b != b'\n').collect(),
            // Random printable ASCII with JSON punctuation.
            3 => {
                let alphabet = b"{}[]\":,0123456789.eE+-truefalsnl \\abc";
                (0..rng.below(200)).map(|_| alphabet[rng.below(alphabet.len() as u64) as usize]).collect()
            }
            // Deep nesting.
            4 => {
                let d = 10 + rng.below(5000) as usize;
                format!(r#"{{"scene_id":"{id}","model":"{model}","plan":{}1{}}}"#, "[".repeat(d), "]".repeat(d)).into_bytes()
            }
            // Absurd numbers in an otherwise fine plan.
            5 => {
                let v = ["1e308", "-1e300", "1e999", "NaN", "Infinity", "99999", "-0", "1e-320"][rng.below(8) as usize];
                format!(r#"{{"scene_id":"{id}","model":"{model}","plan":{{"intent":"x","walking_cmd":[{v},0,0],"walking_duration":{v},"keyframes":[[{v},0,0]]}}}}"#).into_bytes()
            }
            // Wrong types everywhere.
            6 => {
                let v = [r#""abc""#, "null", "[]", "{}", "true", "[1,2]", r#"[[1,"a",3]]"#, r#"{"t":"x"}"#][rng.below(8) as usize];
                format!(r#"{{"scene_id":"{id}","model":"{model}","plan":{{"intent":{v},"walking_cmd":{v},"walking_duration":{v},"keyframes":{v},"confidence":{v}}}}}"#).into_bytes()
            }
            // Responses with broken fences, braces and escapes.
            7 => {
                let r = [
                    r#"```json\n{\"walking_cmd\": [0,0"#,
                    r#"{{{{{{"#,
                    r#"}}}} {\"keyframes\": [[0.5, 0, 0]]} ```"#,
                    r#"```\n```\n```json"#,
                    r#"\\\"{\"a\":\"\\\"}\"}"#,
                    r#"plan: {\"intent\": \"don't catch\", \"walking_cmd\": [0, 0.5, 0], \"walking_duration\": 1}"#,
                ][rng.below(6) as usize];
                format!(r#"{{"scene_id":"{id}","model":"{model}","response":"{r}"}}"#).into_bytes()
            }
            // Missing/odd identifiers.
            8 => [
                format!(r#"{{"model":"{model}","plan":{{}}}}"#),
                format!(r#"{{"scene_id":"{id}","plan":{{}}}}"#),
                format!(r#"{{"scene_id":{},"model":"{model}"}}"#, rng.below(1000)),
                format!(r#"{{"scene_id":"{id}","model":""}}"#),
                "[]".to_string(),
                "\"just a string\"".to_string(),
                "null".to_string(),
            ][rng.below(7) as usize]
            .clone()
            .into_bytes(),
            // Errors, blank lines, whitespace, CRLF.
            9 => format!(r#"{{"scene_id":"{id}","model":"{model}","error":{}}}"#, ["\"429\"", "null", "false", "{}", "\"\""][rng.below(5) as usize]).into_bytes(),
            10 => b"   \t ".to_vec(),
            11 => {
                let mut v = g.to_vec();
                v.push(b'\r');
                v
            }
            // A long (but under the cap) response full of braces.
            12 => format!(r#"{{"scene_id":"{id}","model":"{model}","response":"{}"}}"#, "{".repeat(200_000)).into_bytes(),
            // Duplicated keys.
            13 => format!(r#"{{"scene_id":"{id}","scene_id":"{id}","model":"{model}","plan":{{"walking_cmd":[0,0,0],"walking_cmd":[1,0,0],"walking_duration":1}}}}"#).into_bytes(),
            // Keyframe objects with odd keys.
            14 => format!(r#"{{"scene_id":"{id}","model":"{model}","plan":{{"walking_cmd":[0,0,0],"keyframes":[{{"t":0.1}},{{"hands":[0.5,0,0]}},{{"left_hand":[0.5,0,0],"left_hand":[0.1,0,0]}}]}}}}"#).into_bytes(),
            _ => format!("line {i} is not json").into_bytes(),
        };
        lines.push(line);
    }
    // Huge lines: one over the 16 MiB cap (skipped, never held), one just under 1 MiB.
    let huge_at = lines.len();
    let mut huge = br#"{"scene_id":"x","model":"m","response":""#.to_vec();
    huge.extend(std::iter::repeat_n(b'a', 17 << 20));
    huge.extend(br#""}"#);
    lines.push(huge);
    lines.push(
        format!(
            r#"{{"scene_id":"{}","model":"big","response":"{}"}}"#,
            ids[0],
            "x ".repeat(500_000)
        )
        .into_bytes(),
    );

    let p = work.join("fuzz.jsonl");
    {
        let mut f = std::io::BufWriter::new(std::fs::File::create(&p).unwrap());
        for l in &lines {
            f.write_all(l).unwrap();
            f.write_all(b"\n").unwrap();
        }
        // The last line is truncated without a newline.
        f.write_all(&good[0].as_bytes()[..20]).unwrap();
    }
    let total_lines = lines.len() as u64 + 1;

    let json = work.join("r.json");
    let out = run(
        "rh-score",
        &[
            p.to_str().unwrap(),
            "--dataset",
            ds.to_str().unwrap(),
            "--json",
            json.to_str().unwrap(),
            "--figures",
            work.join("figs").to_str().unwrap(),
        ],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "stderr:\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let r: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let input = &r["input"];
    assert_eq!(input["lines"], total_lines);
    // Every line is accounted for: scored, lost, duplicate, blank, a skipped-line warning,
    // or an error line later replaced by its retry (retry_after_error).
    let skipped: u64 = input["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|w| {
            [
                "malformed_json",
                "not_an_object",
                "missing_scene_id",
                "missing_model",
                "bad_model",
                "unknown_scene_id",
                "invalid_utf8",
                "line_too_long",
                "invalid_scene",
                "json_array",
                "outside_subset",
                "retry_after_error",
            ]
            .contains(&w["kind"].as_str().unwrap())
        })
        .map(|w| w["count"].as_u64().unwrap())
        .sum();
    let acc = input["decisions_scored"].as_u64().unwrap()
        + input["decisions_lost"].as_u64().unwrap()
        + input["duplicates"].as_u64().unwrap()
        + input["blank_lines"].as_u64().unwrap()
        + skipped;
    assert_eq!(acc, total_lines, "{input}");
    // Every dropped line is counted under a kind that names it.
    let dropped: u64 = input["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|w| w["dropped"] == true)
        .map(|w| w["count"].as_u64().unwrap())
        .sum();
    assert_eq!(input["dropped_lines"].as_u64(), Some(dropped), "{input}");
    let too_long = input["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|w| w["kind"] == "line_too_long")
        .expect("line_too_long counted");
    assert_eq!(too_long["count"], 1);
    assert_eq!(too_long["first_lines"][0], huge_at as u64 + 1);
    assert!(input["decisions_scored"].as_u64().unwrap() > 100);
}
