//! The README's examples work as written (issue 25).
//!
//! Every fenced ```` ```sh ```` block of `README.md` is a list of shell commands (a line
//! ending in `\` continues on the next; blank lines and `#` comment lines are not
//! commands). The blocks run in README order, each command by `bash -c` with `set -e -o
//! pipefail`, all in one temporary directory (so a later block uses the dataset an
//! earlier one built), with the binaries of this build first on `PATH`, offline
//! (`HF_HUB_OFFLINE=1`) and with every cache inside the temporary directory. A command
//! fails the test when it exits non-zero or runs longer than `COMMAND_LIMIT`.
//!
//! **The skip rule.** A block is not run when the line just before its opening fence is
//! an HTML comment `<!-- not run by tests: REASON -->` (invisible on the rendered page).
//! That is for what cannot run offline in seconds: the quick start itself, cargo builds,
//! rendered builds, model servers, network APIs, the Hub and clusters. A skipped block's
//! `rh-pipeline` / `rh-score` commands are still checked: each `--flag` they use must
//! appear in the `--help` of the (sub)command — as must every flag of the usage
//! synopses (the plain ```` ``` ```` blocks whose lines start with a program name), in
//! the README and in every `docs/*.md`.
//!
//! The README also stays a user's document: at most `MAX_README_LINES` lines.

use rh_e2e::bin;
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const MAX_README_LINES: usize = 450;
const SKIP_MARKER: &str = "<!-- not run by tests:";
const COMMAND_LIMIT: Duration = Duration::from_secs(90);
const PROGRAMS: [&str; 2] = ["rh-pipeline", "rh-score"];

fn readme() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md"))
        .expect("README.md")
}

/// A fenced code block: its language, the line of its opening fence (1-based), the skip
/// reason when marked, and its commands with their first line numbers.
struct Block {
    lang: String,
    line: usize,
    skip: Option<String>,
    commands: Vec<(usize, String)>,
}

fn blocks(text: &str) -> Vec<Block> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let Some(lang) = lines[i].trim_start().strip_prefix("```") else {
            i += 1;
            continue;
        };
        let previous = lines[..i].iter().rev().find(|l| !l.trim().is_empty());
        let skip = previous.and_then(|l| {
            let reason = l.trim().strip_prefix(SKIP_MARKER)?.strip_suffix("-->")?;
            Some(reason.trim().to_string())
        });
        let mut block = Block {
            lang: lang.trim().to_string(),
            line: i + 1,
            skip,
            commands: Vec::new(),
        };
        i += 1;
        let mut pending: Option<(usize, String)> = None;
        while i < lines.len() && !lines[i].trim_start().starts_with("```") {
            let line = lines[i].trim();
            // A usage synopsis continues a command on indented lines.
            if block.lang.is_empty() && lines[i].starts_with(' ') {
                if let Some((_, last)) = block.commands.last_mut() {
                    last.push(' ');
                    last.push_str(line);
                }
                i += 1;
                continue;
            }
            match pending.take() {
                Some((at, mut command)) => {
                    command.push(' ');
                    command.push_str(line.trim_end_matches('\\').trim());
                    if line.ends_with('\\') {
                        pending = Some((at, command));
                    } else {
                        block.commands.push((at, command));
                    }
                }
                None if line.is_empty() || line.starts_with('#') => {}
                None => {
                    let command = line.trim_end_matches('\\').trim().to_string();
                    if line.ends_with('\\') {
                        pending = Some((i + 1, command));
                    } else {
                        block.commands.push((i + 1, command));
                    }
                }
            }
            i += 1;
        }
        assert!(
            i < lines.len(),
            "README: unclosed code block at line {}",
            block.line
        );
        if let Some(last) = pending {
            block.commands.push(last);
        }
        out.push(block);
        i += 1;
    }
    out
}

/// The command without a trailing shell comment (` # ...`).
fn strip_comment(command: &str) -> &str {
    command.find(" #").map_or(command, |at| &command[..at])
}

/// Each `rh-pipeline` / `rh-score` invocation in a command line: (program, arguments),
/// split at pipes and command separators. In a usage synopsis (`shell = false`) a `|`
/// means "or" unless a program name follows it.
fn invocations(command: &str, shell: bool) -> Vec<(String, Vec<String>)> {
    let mut parts: Vec<String> = Vec::new();
    for part in strip_comment(command).split(['|', ';', '&']) {
        let starts_program = PROGRAMS
            .iter()
            .any(|p| part.split_whitespace().next() == Some(*p));
        match parts.last_mut() {
            Some(last) if !shell && !starts_program => {
                last.push_str(" | ");
                last.push_str(part);
            }
            _ => parts.push(part.to_string()),
        }
    }
    parts
        .iter()
        .filter_map(|part| {
            let mut words = part
                .split_whitespace()
                .map(|w| w.trim_matches(['"', '\'', '[', ']', '(', ')']).to_string());
            let program = words.next()?;
            PROGRAMS
                .contains(&program.as_str())
                .then(|| (program, words.collect()))
        })
        .collect()
}

/// `PROGRAM [SUBCOMMAND] --help`; the subcommand is the first argument when the program's
/// own help lists it as one.
fn help_text(program: &str, args: &[String]) -> (String, String) {
    let top = help(program, &[]);
    let sub = args.first().filter(|a| !a.starts_with('-')).filter(|a| {
        top.lines()
            .any(|l| l.trim_start().split_whitespace().next() == Some(a.as_str()))
    });
    match sub {
        Some(sub) => (format!("{program} {sub}"), help(program, &[sub.as_str()])),
        None => (program.to_string(), top),
    }
}

fn help(program: &str, sub: &[&str]) -> String {
    let out = Command::new(bin(program))
        .args(sub)
        .arg("--help")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{program} {sub:?} --help failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr)
}

/// Flags used by `command` that its program's `--help` does not list.
fn unknown_flags(command: &str, shell: bool) -> Vec<String> {
    let mut unknown = Vec::new();
    for (program, args) in invocations(command, shell) {
        let (name, text) = help_text(&program, &args);
        for arg in &args {
            let Some(flag) = arg.strip_prefix("--") else {
                continue;
            };
            let flag = flag.split(['=', '[', ']']).next().unwrap();
            if flag.is_empty() || flag == "help" {
                continue;
            }
            let listed = text
                .split(|c: char| !(c.is_alphanumeric() || c == '-'))
                .any(|w| w == format!("--{flag}"));
            if !listed {
                unknown.push(format!("{name}: --{flag}"));
            }
        }
    }
    unknown
}

#[test]
fn readme_stays_a_users_document() {
    let lines = readme().lines().count();
    assert!(
        lines <= MAX_README_LINES,
        "README.md has {lines} lines (limit {MAX_README_LINES}): move details to docs/"
    );
}

/// The README and every `docs/*.md` file, by name.
fn documents() -> Vec<(String, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut docs = vec![("README.md".to_string(), readme())];
    let mut names: Vec<_> = std::fs::read_dir(root.join("docs"))
        .expect("docs/")
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.ends_with(".md"))
        .collect();
    names.sort();
    for name in names {
        let text = std::fs::read_to_string(root.join("docs").join(&name)).unwrap();
        docs.push((format!("docs/{name}"), text));
    }
    docs
}

#[test]
fn every_documented_flag_exists() {
    let mut unknown = Vec::new();
    let mut checked = 0;
    for (name, text) in documents() {
        for block in blocks(&text) {
            let synopsis = block.lang.is_empty();
            if !(synopsis || block.lang == "sh") {
                continue;
            }
            for (line, command) in &block.commands {
                if synopsis && !PROGRAMS.iter().any(|p| command.starts_with(p)) {
                    continue;
                }
                checked += invocations(command, !synopsis).len();
                for flag in unknown_flags(command, !synopsis) {
                    unknown.push(format!("{name} line {line}: {flag}"));
                }
            }
        }
    }
    assert!(
        checked >= 30,
        "only {checked} invocations found in README.md and docs/"
    );
    assert!(
        unknown.is_empty(),
        "documented flags the programs do not know:\n{}",
        unknown.join("\n")
    );
}

/// Runs one command in `dir`; Err(why) when it fails or runs too long.
fn run_command(dir: &Path, path: &str, command: &str) -> Result<Duration, String> {
    // One file for stdout and stderr (one shared offset), read back on failure.
    let log = dir.join(".readme-command.log");
    let out = std::fs::File::create(&log).unwrap();
    let start = Instant::now();
    let mut child = Command::new("bash")
        .arg("-c")
        .arg(format!("set -e -o pipefail\n{command}"))
        .current_dir(dir)
        .env("PATH", path)
        .env("HOME", dir.join(".home"))
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .env("HF_HOME", dir.join(".hf"))
        .env("HF_HUB_OFFLINE", "1")
        .env("RH_EXEC_CACHE", dir.join(".exec-cache"))
        .env("RH_LLM_CACHE", dir.join(".llm-cache"))
        .env_remove("RH_DATASET")
        .stdin(Stdio::null())
        .stdout(out.try_clone().unwrap())
        .stderr(out)
        .process_group(0)
        .spawn()
        .unwrap();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let output = std::fs::read_to_string(&log).unwrap_or_default();
            let lines: Vec<&str> = output.lines().collect();
            let tail = match lines.len() {
                0 => "(no output)".to_string(),
                n => lines[n.saturating_sub(20)..].join("\n"),
            };
            return if status.success() {
                Ok(start.elapsed())
            } else {
                Err(format!("{status}; last output:\n{tail}"))
            };
        }
        if start.elapsed() > COMMAND_LIMIT {
            // The whole process group: bash and what it started.
            unsafe { libc::kill(-(child.id() as i32), libc::SIGKILL) };
            let _ = child.wait();
            return Err(format!(
                "still running after {} s: too long for a README example; shorten it or mark its block `{SKIP_MARKER} REASON -->`",
                COMMAND_LIMIT.as_secs()
            ));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn readme_commands_run_as_written() {
    let text = readme();
    let work = tempfile::tempdir().unwrap();
    let bin_dir = bin("rh-pipeline").parent().unwrap().to_path_buf();
    let path = format!(
        "{}:{}",
        bin_dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let (mut ran, mut skipped, mut failures) = (0, 0, Vec::new());
    for block in blocks(&text).into_iter().filter(|b| b.lang == "sh") {
        if let Some(reason) = &block.skip {
            assert!(
                !reason.is_empty(),
                "README line {}: a skipped block must say why",
                block.line
            );
            skipped += 1;
            continue;
        }
        for (line, command) in &block.commands {
            match run_command(work.path(), &path, command) {
                Ok(took) => {
                    eprintln!(
                        "README line {line}: ok in {:.1} s: {command}",
                        took.as_secs_f64()
                    );
                    ran += 1;
                }
                Err(why) => failures.push(format!("README line {line}: `{command}`: {why}")),
            }
        }
    }
    eprintln!("{ran} README commands ran, {skipped} blocks skipped by their marker");
    assert!(
        failures.is_empty(),
        "README commands that fail as written:\n\n{}",
        failures.join("\n\n")
    );
    assert!(
        ran >= 10,
        "only {ran} README commands ran; the examples lost their runnable part"
    );
}
