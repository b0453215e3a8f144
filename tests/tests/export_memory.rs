//! `rh-score export` streams the scene table (issue 28): its peak resident memory on a
//! large label-only table is at most 1.3 × that on 10³ scenes. The tables are synthetic
//! (`rh-score make-fixture`: the scene table's columns). The large table has 10⁴ scenes
//! by default (writing a fixture's 10⁵ spec files takes minutes of I/O);
//! `RH_EXPORT_MEMORY_N=100000` measures the acceptance's 10⁵ (docs/harnesses.md has the
//! figures, also for real builds). Each export's peak is its own (`wait4`).

use rh_e2e::bin;
use std::path::Path;
use std::process::Command;

/// Runs `rh-score ARGS` to completion and returns its peak RSS in MiB (asserting success).
fn peak_rss_mib(args: &[&str]) -> f64 {
    let child = Command::new(bin("rh-score"))
        .args(args)
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mut status = 0;
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: wait4 on our own child, writing into valid pointers.
    let pid = unsafe { libc::wait4(child.id() as i32, &mut status, 0, &mut usage) };
    assert_eq!(pid, child.id() as i32);
    assert!(
        libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        "rh-score {args:?} failed"
    );
    usage.ru_maxrss as f64 / 1024.0 // kilobytes on Linux
}

fn export_peak(dir: &Path, n: u32) -> f64 {
    let ds = dir.join(format!("ds{n}"));
    rh_e2e::make_fixture(&ds, n, 1);
    let out = dir.join(format!("out{n}"));
    let (ds, out) = (ds.to_str().unwrap(), out.to_str().unwrap());
    peak_rss_mib(&["export", "--dataset", ds, "--out", out, "--split", "all"])
}

#[test]
fn export_memory_is_flat_in_the_number_of_scenes() {
    let tmp = tempfile::tempdir().unwrap();
    let small = export_peak(tmp.path(), 1_000);
    let n: u32 = std::env::var("RH_EXPORT_MEMORY_N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(10_000);
    let large = export_peak(tmp.path(), n);
    eprintln!(
        "export peak RSS: 1000 scenes {small:.1} MiB, {n} scenes {large:.1} MiB ({:.2}x)",
        large / small
    );
    assert!(
        large <= 1.3 * small,
        "{n} scenes: {large:.1} MiB > 1.3 x {small:.1} MiB"
    );
}
