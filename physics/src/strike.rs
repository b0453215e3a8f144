//! The strike test (SPEC §6, §12) — one rule for the counterfactual label and the
//! executor: the label's `danger_present` (`simulate` with the standing body as fixed
//! colliders) and the executor's `struck` (the moving body as kinematic links) both feed
//! a [`StrikeMonitor`] step by step and judge with [`StrikeRule::is_strike`].
//!
//! * A **window** opens at a step where the hazard touches the body and runs
//!   `window_steps` steps after it (both ends included). It keeps the largest speed of the
//!   hazard's contact point relative to the touched link ([`contact_point_speed`]) at a
//!   touch, and adds up the normal impulse the links receive, per link.
//! * The window is a **strike** as soon as `speed ≥ speed_min` and `impulse ≥
//!   impulse_min`, or `impulse ≥ impulse_heavy` at any speed. Both numbers only grow
//!   within a window, so judging at its first qualifying step or at its end is the same
//!   verdict; the label follows a strike window to its end (its recorded numbers are the
//!   whole window's), the executor stops at the verdict.
//! * A window that ends without a strike closes; the next touch opens a new one (a
//!   pendulum that grazes the body and comes back hard strikes on its return).

use crate::spec::LabelConfig;
use rapier3d::prelude::*;

/// The thresholds of the strike test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrikeRule {
    pub speed_min: f64,
    pub impulse_min: f64,
    pub impulse_heavy: f64,
    /// Steps a window runs after the touch that opened it.
    pub window_steps: u32,
}

impl StrikeRule {
    pub fn new(
        speed_min: f64,
        impulse_min: f64,
        impulse_heavy: f64,
        window_s: f64,
        dt: f64,
    ) -> Self {
        StrikeRule {
            speed_min,
            impulse_min,
            impulse_heavy,
            window_steps: (window_s / dt).round() as u32,
        }
    }

    /// The label's thresholds (`configs/labels.toml`, stored in every spec).
    pub fn of_labels(l: &LabelConfig, dt: f64) -> Self {
        Self::new(
            l.strike_speed_min,
            l.strike_impulse_min,
            l.strike_impulse_heavy,
            l.strike_window_s,
            dt,
        )
    }

    /// The strike test on one window's largest contact speed and total impulse.
    pub fn is_strike(&self, speed: f64, impulse: f64) -> bool {
        (speed >= self.speed_min && impulse >= self.impulse_min) || impulse >= self.impulse_heavy
    }
}

/// One window's numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct StrikeWindow {
    /// The step of the touch that opened it.
    pub start: u32,
    /// Largest relative contact-point speed at a touch in the window (m/s).
    pub speed: f64,
    /// Total normal impulse on the body's links over the window (N·s).
    pub impulse: f64,
    /// The same, per link.
    pub per_part: Vec<f64>,
}

impl StrikeWindow {
    pub fn new(start: u32, parts: usize) -> Self {
        StrikeWindow {
            start,
            speed: 0.0,
            impulse: 0.0,
            per_part: vec![0.0; parts],
        }
    }

    /// Adds one step: the touch's speed (if the hazard touches the body this step) and
    /// the impulse each link received.
    pub fn add(&mut self, touch: Option<f64>, impulses: &[f64]) {
        if let Some(speed) = touch {
            self.speed = self.speed.max(speed);
        }
        for (acc, x) in self.per_part.iter_mut().zip(impulses) {
            *acc += x;
        }
        self.impulse += impulses.iter().sum::<f64>();
    }

    /// Index of the link that took the largest impulse in the window (the first on a tie).
    pub fn heaviest_part(&self) -> usize {
        self.per_part
            .iter()
            .enumerate()
            .fold(
                (0, f64::MIN),
                |best, (i, &x)| if x > best.1 { (i, x) } else { best },
            )
            .0
    }
}

/// Follows the strike test over a run, one call per physics step.
#[derive(Debug, Clone)]
pub struct StrikeMonitor {
    rule: StrikeRule,
    parts: usize,
    open: Option<StrikeWindow>,
    first: Option<StrikeWindow>,
    strike: Option<StrikeWindow>,
    first_touch: Option<u32>,
}

impl StrikeMonitor {
    pub fn new(rule: StrikeRule, parts: usize) -> Self {
        StrikeMonitor {
            rule,
            parts,
            open: None,
            first: None,
            strike: None,
            first_touch: None,
        }
    }

    /// One step: `touch` is the largest relative contact speed of the hazard at the
    /// body's links this step (`None`: no touch), `impulses` what each link received.
    pub fn step(&mut self, step: u32, touch: Option<f64>, impulses: &[f64]) {
        if touch.is_some() && self.first_touch.is_none() {
            self.first_touch = Some(step);
        }
        if let Some(s) = self.strike.as_mut() {
            // A strike: its window is followed to its end, nothing after.
            if step <= s.start + self.rule.window_steps {
                s.add(touch, impulses);
            }
            return;
        }
        if self.open.is_none() && touch.is_some() {
            self.open = Some(StrikeWindow::new(step, self.parts));
        }
        let Some(w) = self.open.as_mut() else {
            return;
        };
        w.add(touch, impulses);
        if self.rule.is_strike(w.speed, w.impulse) {
            self.strike = self.open.take();
        } else if step >= w.start + self.rule.window_steps {
            let closed = self.open.take();
            if self.first.is_none() {
                self.first = closed;
            }
        }
    }

    /// The strike, once the test has passed.
    pub fn strike(&self) -> Option<&StrikeWindow> {
        self.strike.as_ref()
    }

    /// A strike whose window is over at `step` (the counterfactual run may stop).
    pub fn strike_over(&self, step: u32) -> bool {
        self.strike
            .as_ref()
            .is_some_and(|s| step >= s.start + self.rule.window_steps)
    }

    /// Whether a window is being followed (no verdict yet).
    pub fn window_open(&self) -> bool {
        self.open.is_some()
    }

    /// What the run records: the strike, else the first window (closed, or still open
    /// when the run ended), else `None` (the hazard never touched the body).
    pub fn report(&self) -> Option<&StrikeWindow> {
        self.strike
            .as_ref()
            .or(self.first.as_ref())
            .or(self.open.as_ref())
    }

    /// The first step the hazard touched the body.
    pub fn first_touch(&self) -> Option<u32> {
        self.first_touch
    }
}

/// Speed of the hazard's contact point relative to the body link `other` at that point:
/// `v + ω × (p − c)` of the hazard with its velocities of the step before (`linvel`,
/// `angvel`: before the contact impulse), `p` the hazard's deepest (or nearest) point
/// against the link now and `c` its centre of mass now, minus the link's own velocity at
/// `p` (zero for the standing body's fixed links).
pub fn contact_point_speed(
    world: &PhysicsWorld,
    hazard: ColliderHandle,
    linvel: Vector,
    angvel: Vector,
    other: ColliderHandle,
) -> f64 {
    let (h, o) = (&world.colliders[hazard], &world.colliders[other]);
    let com = h.parent().map_or(h.position().translation, |b| {
        world.bodies[b].center_of_mass()
    });
    // The contact query gives the hazard's deepest (or nearest) point even when the
    // shapes overlap; should it find none, the centre of mass stands in.
    let point = match rapier3d::parry::query::contact(
        h.position(),
        h.shape(),
        o.position(),
        o.shape(),
        0.1,
    ) {
        Ok(Some(c)) => c.point1,
        _ => com,
    };
    let v = linvel + angvel.cross(point - com);
    let link = o
        .parent()
        .map_or(Vector::ZERO, |b| world.bodies[b].velocity_at_point(point));
    (v - link).length() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule() -> StrikeRule {
        StrikeRule::new(0.5, 0.05, 2.0, 0.25, 1.0 / 240.0)
    }

    #[test]
    fn a_window_needs_speed_and_impulse_or_a_heavy_push() {
        let r = rule();
        assert_eq!(r.window_steps, 60);
        assert!(r.is_strike(0.5, 0.05));
        assert!(!r.is_strike(0.49, 1.0));
        assert!(!r.is_strike(3.0, 0.049));
        assert!(r.is_strike(0.0, 2.0));
    }

    #[test]
    fn a_graze_then_a_blow_is_a_strike_on_the_blow_and_its_window_is_whole() {
        let mut m = StrikeMonitor::new(rule(), 2);
        // A slow graze at step 10: no strike; its window closes at step 70.
        m.step(10, Some(0.2), &[0.01, 0.0]);
        for k in 11..=70 {
            m.step(k, None, &[0.0, 0.0]);
        }
        assert!(!m.window_open() && m.strike().is_none());
        assert_eq!(m.report().unwrap().start, 10);
        // A blow at step 100 on part 1: a strike at once; followed to step 160.
        m.step(100, Some(3.0), &[0.0, 0.2]);
        assert_eq!(m.strike().unwrap().start, 100);
        assert!(!m.strike_over(159));
        m.step(130, None, &[0.0, 0.3]);
        m.step(161, Some(9.0), &[0.0, 5.0]);
        assert!(m.strike_over(160));
        let s = m.report().unwrap();
        assert_eq!((s.start, s.speed, s.heaviest_part()), (100, 3.0, 1));
        assert!((s.impulse - 0.5).abs() < 1e-12);
        assert_eq!(m.first_touch(), Some(10));
    }
}
