//! The Slurm path, run for real: `scripts/slurm_cluster_test.sh` starts a one-node Slurm
//! cluster on localhost (munged, slurmctld, slurmd; everything in a temp dir, free ports),
//! submits `cluster/slurm_build.sbatch` unchanged as a 4-task job array of a label-only
//! build, cancels one task mid-way with `scancel`, resubmits it (it must say it resumed),
//! merges the shards and compares the result with a single build, file by file.
//!
//! Never skipped: where Slurm or munge are missing or cannot start, the script fails
//! naming what is missing and what to install (`scripts/setup.sh` installs them).

use std::path::Path;
use std::process::Command;

#[test]
fn slurm_job_array_with_a_cancelled_task_merges_into_the_single_build() {
    let rh_pipeline = rh_e2e::bin("rh-pipeline");
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let out = Command::new("bash")
        .arg(repo.join("scripts/slurm_cluster_test.sh"))
        .arg(rh_pipeline.parent().unwrap())
        .output()
        .expect("bash runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "the Slurm cluster test failed (exit {:?})\nstdout:\n{stdout}\nstderr:\n{stderr}",
        out.status.code()
    );
    for needle in [
        "slurm e2e: cluster up",
        "slurm e2e: cancelled task",
        "slurm e2e: resubmitted task 0 as",
        "resumed ",
        "slurm e2e: ok: merge of 4 Slurm shards",
    ] {
        assert!(stdout.contains(needle), "no '{needle}' in:\n{stdout}");
    }

    // Cleaned up: the temp dir is gone and the daemons it started are not running.
    let line = |prefix: &str| -> String {
        stdout
            .lines()
            .find_map(|l| l.strip_prefix(prefix))
            .unwrap_or_else(|| panic!("no '{prefix}' line in:\n{stdout}"))
            .to_string()
    };
    let temp = line("slurm e2e: temp dir ");
    assert!(!Path::new(&temp).exists(), "{temp} was not removed");
    let stopped = line("slurm e2e: daemons stopped (pids ");
    let pids: Vec<&str> = stopped
        .split(')')
        .next()
        .unwrap()
        .split_whitespace()
        .collect();
    assert_eq!(pids.len(), 3, "munged, slurmctld, slurmd: {stopped}");
    for pid in pids {
        let cmdline = std::fs::read(format!("/proc/{pid}/cmdline")).unwrap_or_default();
        let cmdline = String::from_utf8_lossy(&cmdline);
        assert!(
            !(cmdline.contains("slurm") || cmdline.contains("munge")),
            "daemon {pid} still runs: {cmdline}"
        );
    }
}
