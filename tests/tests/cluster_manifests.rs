//! `cluster/k8s_build_job.yaml`, checked offline: it parses, validates against the
//! Kubernetes Job schema (the `kubernetes-validate` package from PyPI, installed by
//! `scripts/setup.sh`, with its bundled schemas; strict: unknown fields are errors), and
//! the fields the docs rely on hold: an Indexed Job whose completions, parallelism and
//! shard count agree, and a command that, run by the container's shell with
//! `JOB_COMPLETION_INDEX` set, builds exactly that shard.

use rh_e2e::{python, run_ok};
use std::path::Path;

/// The Kubernetes version the manifest is validated against (`backoffLimitPerIndex` is GA
/// from 1.33).
const K8S_VERSION: &str = "1.33.0";

fn manifest() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .join("cluster/k8s_build_job.yaml")
}

#[test]
fn k8s_job_validates_against_the_job_schema_and_shards_by_completion_index() {
    let path = manifest();
    let report = python(&format!(
        r#"
import copy, json, yaml, kubernetes_validate
docs = list(yaml.safe_load_all(open({path:?})))
assert len(docs) == 1, f"{{len(docs)}} documents"
job = docs[0]
kubernetes_validate.validate(job, {K8S_VERSION:?}, strict=True)
def rejected(mutate):
    bad = copy.deepcopy(job)
    mutate(bad)
    try:
        kubernetes_validate.validate(bad, {K8S_VERSION:?}, strict=True)
        return False
    except kubernetes_validate.ValidationError:
        return True
checks = {{
    "rejects_a_mistyped_field": rejected(lambda j: j["spec"].update(completions="sixteen")),
    "rejects_an_unknown_field": rejected(
        lambda j: j["spec"]["template"]["spec"]["containers"][0].update(comand=["x"])),
}}
print(json.dumps({{"job": job, "checks": checks}}))
"#,
        path = path.display().to_string()
    ));
    let report: serde_json::Value = serde_json::from_str(report.trim()).unwrap();
    // The validator really validates (a broken copy fails).
    for (name, ok) in report["checks"].as_object().unwrap() {
        assert_eq!(ok, true, "{name}");
    }
    let job = &report["job"];
    assert_eq!(job["apiVersion"], "batch/v1");
    assert_eq!(job["kind"], "Job");
    let spec = &job["spec"];
    assert_eq!(spec["completionMode"], "Indexed");
    let shards = spec["completions"].as_u64().expect("completions");
    assert_eq!(spec["parallelism"].as_u64(), Some(shards));
    let pod = &spec["template"]["spec"];
    // backoffLimitPerIndex needs restartPolicy Never.
    assert_eq!(pod["restartPolicy"], "Never");
    let container = &pod["containers"][0];
    assert_eq!(container["command"], serde_json::json!(["/bin/sh", "-c"]));
    let script = container["args"][0].as_str().expect("one shell command");
    assert!(
        script.contains("$JOB_COMPLETION_INDEX"),
        "command does not use JOB_COMPLETION_INDEX: {script}"
    );

    // Run the command with the container's shell, JOB_COMPLETION_INDEX = 3 and a stand-in
    // rh-pipeline that records its arguments: the shard is 3 of `completions`.
    let dir = tempfile::tempdir().unwrap();
    let shim = dir.path().join("rh-pipeline");
    let argv_file = dir.path().join("argv");
    std::fs::write(
        &shim,
        format!(
            "#!/bin/sh\nfor a in \"$@\"; do printf '%s\\n' \"$a\"; done > {}\n",
            argv_file.display()
        ),
    )
    .unwrap();
    std::process::Command::new("chmod")
        .arg("+x")
        .arg(&shim)
        .status()
        .unwrap();
    let status = std::process::Command::new("/bin/sh")
        .arg("-c")
        .arg(script)
        .env("JOB_COMPLETION_INDEX", "3")
        .env(
            "PATH",
            format!(
                "{}:{}",
                dir.path().display(),
                std::env::var("PATH").unwrap()
            ),
        )
        .status()
        .unwrap();
    assert!(status.success());
    let argv: Vec<String> = std::fs::read_to_string(&argv_file)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect();
    let value = |flag: &str| -> String {
        let i = argv.iter().position(|a| a == flag).unwrap_or_else(|| {
            panic!("no {flag} in {argv:?}");
        });
        argv[i + 1].clone()
    };
    assert_eq!(argv[0], "build");
    assert_eq!(value("--shard"), format!("3/{shards}"));
    assert_eq!(value("--out"), "/data/shards/3");
    assert_eq!(value("--n"), "10000");

    // The real CLI accepts those arguments and writes that shard (a small label-only
    // build in a temp dir instead of 10,000 rendered scenes on /data).
    let out = dir.path().join("shard3");
    let mut args: Vec<String> = argv.clone();
    let set = |args: &mut Vec<String>, flag: &str, v: &str| {
        let i = args.iter().position(|a| a == flag).unwrap();
        args[i + 1] = v.to_string();
    };
    set(&mut args, "--n", "64");
    set(&mut args, "--jobs", "1");
    set(&mut args, "--out", out.to_str().unwrap());
    args.extend(["--no-render".into(), "--quiet".into()]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    run_ok("rh-pipeline", &args);
    assert!(out
        .join(format!("data/test-00003-of-{shards:05}.parquet"))
        .is_file());
}
