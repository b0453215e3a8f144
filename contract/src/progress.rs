//! Progress for logs: when stderr is not a terminal (a log file, CI), a line every few
//! seconds from a background thread — done of total, rate, ETA — so that a long step
//! (a rendered build, execution videos: 13–15 s a decision) is never silent for minutes.
//! On a terminal the programs draw an `indicatif` bar instead.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Seconds between progress lines in a log.
pub const LOG_EVERY_S: f64 = 10.0;

struct Shared {
    done: AtomicU64,
    stop: AtomicBool,
}

/// Prints `"{what}: done/total {unit} · rate/s · ETA …"` every `every` until dropped.
pub struct ProgressLog {
    shared: Arc<Shared>,
    thread: Option<std::thread::JoinHandle<()>>,
}

/// "1m05s".
pub fn eta_text(secs: f64) -> String {
    let s = secs.max(0.0).round() as u64;
    format!("{}m{:02}s", s / 60, s % 60)
}

impl ProgressLog {
    /// Starts the lines when `show` and stderr is not a terminal; else a silent handle.
    pub fn start(show: bool, what: &str, unit: &str, total: u64, every: Duration) -> ProgressLog {
        let shared = Arc::new(Shared {
            done: AtomicU64::new(0),
            stop: AtomicBool::new(false),
        });
        let thread = (show && !std::io::stderr().is_terminal()).then(|| {
            let (sh, what, unit) = (shared.clone(), what.to_string(), unit.to_string());
            let began = Instant::now();
            std::thread::spawn(move || {
                let mut next = began + every;
                while !sh.stop.load(Ordering::Relaxed) {
                    std::thread::sleep(Duration::from_millis(50).min(every));
                    if Instant::now() < next {
                        continue;
                    }
                    next += every;
                    let done = sh.done.load(Ordering::Relaxed);
                    let secs = began.elapsed().as_secs_f64();
                    let rate = done as f64 / secs.max(1e-9);
                    let eta = if done == 0 {
                        "unknown".into()
                    } else {
                        eta_text(total.saturating_sub(done) as f64 / rate)
                    };
                    crate::note!(
                        "{what}: {done}/{total} {unit} · {rate:.3}/s · {:.0} s elapsed · ETA {eta}",
                        secs
                    );
                }
            })
        });
        ProgressLog { shared, thread }
    }

    pub fn add(&self, n: u64) {
        self.shared.done.fetch_add(n, Ordering::Relaxed);
    }
}

impl Drop for ProgressLog {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
