//! Adaptive concurrency: at most `limit` requests in flight, where `limit` starts at the
//! configured maximum, halves when the server answers 429 (at most once per wave of
//! requests: a 429 to a request started before the last decrease does not decrease it
//! again), pauses every new request until the server's `Retry-After` has passed, and grows
//! back by one after `limit` consecutive successes (additive increase, multiplicative
//! decrease — the TCP rule).

use std::sync::Mutex;
use std::time::{Duration, Instant};
use tokio::sync::Notify;

#[derive(Debug)]
struct State {
    limit: usize,
    in_flight: usize,
    successes: usize,
    paused_until: Option<Instant>,
    last_decrease: Option<Instant>,
    decreases: u64,
}

/// Shared by every request of one client.
#[derive(Debug)]
pub struct Limiter {
    max: usize,
    state: Mutex<State>,
    notify: Notify,
}

/// One request's slot; dropping it frees the slot.
#[derive(Debug)]
pub struct Permit<'a> {
    limiter: &'a Limiter,
    pub started: Instant,
}

impl Drop for Permit<'_> {
    fn drop(&mut self) {
        let mut s = self.limiter.state.lock().expect("limiter lock");
        s.in_flight -= 1;
        drop(s);
        self.limiter.notify.notify_waiters();
    }
}

impl Limiter {
    pub fn new(max: usize) -> Limiter {
        let max = max.max(1);
        Limiter {
            max,
            state: Mutex::new(State {
                limit: max,
                in_flight: 0,
                successes: 0,
                paused_until: None,
                last_decrease: None,
                decreases: 0,
            }),
            notify: Notify::new(),
        }
    }

    /// The current limit (for progress output and tests).
    pub fn limit(&self) -> usize {
        self.state.lock().expect("limiter lock").limit
    }

    /// How many times a 429 lowered the limit.
    pub fn decreases(&self) -> u64 {
        self.state.lock().expect("limiter lock").decreases
    }

    /// Waits for a free slot (and for any `Retry-After` pause to pass).
    pub async fn acquire(&self) -> Permit<'_> {
        loop {
            let wait = {
                let mut s = self.state.lock().expect("limiter lock");
                let now = Instant::now();
                match s.paused_until {
                    Some(t) if t > now => Some(t - now),
                    _ if s.in_flight < s.limit => {
                        s.in_flight += 1;
                        return Permit {
                            limiter: self,
                            started: now,
                        };
                    }
                    _ => None,
                }
            };
            // The short sleep makes a wake-up missed between the check and the wait
            // harmless.
            let nap = wait.unwrap_or(Duration::from_millis(20));
            tokio::select! {
                _ = self.notify.notified() => {}
                _ = tokio::time::sleep(nap) => {}
            }
        }
    }

    pub fn on_success(&self) {
        let mut s = self.state.lock().expect("limiter lock");
        s.successes += 1;
        if s.successes >= s.limit && s.limit < self.max {
            s.limit += 1;
            s.successes = 0;
        }
    }

    /// A 429 to the request holding `permit`; `pause` is how long every request waits.
    pub fn on_rate_limited(&self, permit: &Permit<'_>, pause: Duration) {
        let mut s = self.state.lock().expect("limiter lock");
        let now = Instant::now();
        if s.last_decrease.is_none_or(|t| permit.started >= t) {
            s.limit = (s.limit / 2).max(1);
            s.last_decrease = Some(now);
            s.decreases += 1;
        }
        s.successes = 0;
        let until = now + pause;
        if s.paused_until.is_none_or(|t| t < until) {
            s.paused_until = Some(until);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test]
    async fn halves_once_per_wave_and_grows_back() {
        let l = Limiter::new(8);
        let permits: Vec<_> = futures_lite_join(&l, 8).await;
        assert_eq!(l.limit(), 8);
        // Eight 429s from one wave: one decrease.
        for p in &permits {
            l.on_rate_limited(p, Duration::from_millis(1));
        }
        assert_eq!(l.limit(), 4);
        drop(permits);
        tokio::time::sleep(Duration::from_millis(5)).await;
        // A request started after the decrease lowers it again.
        let p = l.acquire().await;
        l.on_rate_limited(&p, Duration::from_millis(1));
        drop(p);
        assert_eq!(l.limit(), 2);
        // Additive increase: 2 successes → 3, 3 more → 4.
        for _ in 0..5 {
            l.on_success();
        }
        assert_eq!(l.limit(), 4);
    }

    async fn futures_lite_join(l: &Limiter, n: usize) -> Vec<Permit<'_>> {
        let mut v = Vec::new();
        for _ in 0..n {
            v.push(l.acquire().await);
        }
        v
    }

    #[tokio::test]
    async fn pause_holds_new_requests() {
        let l = Limiter::new(2);
        let p = l.acquire().await;
        l.on_rate_limited(&p, Duration::from_millis(150));
        drop(p);
        let t = Instant::now();
        let _q = l.acquire().await;
        assert!(
            t.elapsed() >= Duration::from_millis(140),
            "{:?}",
            t.elapsed()
        );
    }
}
