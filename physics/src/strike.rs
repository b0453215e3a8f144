//! The harm test (specification §6, §12; label rule v5) — one rule for the counterfactual label
//! and the executor: the label's `danger_present` (`simulate` with the standing body as
//! fixed colliders) and the executor's `struck` (the moving body as kinematic links) both
//! feed a [`StrikeMonitor`] step by step with the touches of the body ([`Touch`]) and
//! judge with [`HarmRule`].
//!
//! * Every touch is placed in a **body region** of ISO/TS 15066 Annex A ([`Region`]: the
//!   link it touches, and where on the link for the head and the torso).
//! * A **window** opens at a step where the hazard touches the body and runs
//!   `window_steps` steps after it (both ends included). Per region it keeps the largest
//!   **transient energy** of a touch that pushes (carries an impulse) — the standard's
//!   two-body model, `E = ½ μ v²` with `v` the hazard's contact point's speed along the contact normal relative to the link
//!   and `μ` the reduced mass of the hazard's effective mass at that point and the
//!   region's effective body mass — and the normal impulse the region receives, whose
//!   mean over the window is the **sustained force** (a wardrobe leaning on the body).
//! * The window **harms** as soon as, in some region, the energy reaches the region's
//!   permissible transient energy `(f·F)² / (2k)` (F the permissible quasi-static force,
//!   k the spring constant, f the transient factor) or the sustained force reaches F — or
//!   at once when the hazard is sharp or hot (a touch at all harms: any impulse). Both numbers only
//!   grow within a window, so judging at its first harming step or at its end is the same
//!   verdict; the label follows a harming window to its end (its recorded numbers are the
//!   whole window's), the executor stops at the verdict.
//! * A window that ends without harm closes; the next touch opens a new one (a pendulum
//!   that grazes the body and comes back hard harms on its return).

use crate::body::{LinkShape, Part};
use crate::spec::{HarmLimit, LabelConfig};
use rapier3d::prelude::*;

/// The body regions of ISO/TS 15066 Annex A that the humanoid's links cover.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Region {
    SkullForehead,
    Face,
    Neck,
    BackShoulders,
    Chest,
    Abdomen,
    Pelvis,
    UpperArm,
    Forearm,
    Hand,
    Thigh,
    LowerLeg,
}

impl Region {
    pub const ALL: [Region; 12] = [
        Region::SkullForehead,
        Region::Face,
        Region::Neck,
        Region::BackShoulders,
        Region::Chest,
        Region::Abdomen,
        Region::Pelvis,
        Region::UpperArm,
        Region::Forearm,
        Region::Hand,
        Region::Thigh,
        Region::LowerLeg,
    ];

    /// The name used in `configs/labels.toml` (`[harm.<name>]`) and the `harm_region` column.
    pub fn name(self) -> &'static str {
        match self {
            Region::SkullForehead => "skull_forehead",
            Region::Face => "face",
            Region::Neck => "neck",
            Region::BackShoulders => "back_shoulders",
            Region::Chest => "chest",
            Region::Abdomen => "abdomen",
            Region::Pelvis => "pelvis",
            Region::UpperArm => "upper_arm",
            Region::Forearm => "forearm",
            Region::Hand => "hand",
            Region::Thigh => "thigh",
            Region::LowerLeg => "lower_leg",
        }
    }

    pub fn index(self) -> usize {
        self as usize
    }

    /// The region of a touch of `part` at `local`, the point in the link's own frame
    /// (x forward, z up for the pelvis, torso and head). The head: its lowest 4 cm (where
    /// it sits on the torso) is the neck, its front below the middle the face, the rest
    /// skull and forehead. The torso: its back (the rear third of its depth) and its top
    /// 6 cm are back and shoulders; the front above the middle is the chest, below it the
    /// abdomen. Every other link is one region.
    pub fn of(part: Part, shape: LinkShape, local: [f64; 3]) -> Region {
        let [x, _, z] = local;
        match part {
            Part::Head => {
                let r = shape.bounding_radius();
                if z < -(r - 0.04) {
                    Region::Neck
                } else if x > 0.3 * r && z < 0.4 * r {
                    Region::Face
                } else {
                    Region::SkullForehead
                }
            }
            Part::Torso => {
                let (depth, top) = match shape {
                    LinkShape::Box(h) => (h[0], h[2]),
                    other => (other.bounding_radius(), other.bounding_radius()),
                };
                if x < -depth / 3.0 || z > top - 0.06 {
                    Region::BackShoulders
                } else if z >= 0.0 {
                    Region::Chest
                } else {
                    Region::Abdomen
                }
            }
            Part::Pelvis => Region::Pelvis,
            Part::LeftUpperArm | Part::RightUpperArm => Region::UpperArm,
            Part::LeftForearm | Part::RightForearm => Region::Forearm,
            Part::LeftHand | Part::RightHand => Region::Hand,
            Part::LeftThigh | Part::RightThigh => Region::Thigh,
            Part::LeftShank | Part::RightShank => Region::LowerLeg,
        }
    }
}

/// One region's limits, in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RegionLimit {
    /// Permissible transient energy `(f·F)² / (2k)` (J).
    pub energy_max: f64,
    /// Permissible quasi-static force F (N): the sustained force's limit.
    pub force_max: f64,
    /// Effective body mass of the region (kg).
    pub body_mass: f64,
}

impl RegionLimit {
    /// From the configured numbers and the transient factor f.
    pub fn of(limit: &HarmLimit, transient_factor: f64) -> Self {
        let f = transient_factor * limit.force_n;
        RegionLimit {
            energy_max: f * f / (2.0 * limit.spring_n_per_mm * 1000.0),
            force_max: limit.force_n,
            body_mass: limit.body_mass_kg,
        }
    }

    /// The transient energy of a touch by a hazard of effective mass `mass` (kg; infinite
    /// for an immovable one) whose contact point approaches at `speed` (m/s): ½ μ v².
    pub fn energy(&self, mass: f64, speed: f64) -> f64 {
        let mu = if mass.is_finite() {
            mass * self.body_mass / (mass + self.body_mass)
        } else {
            self.body_mass
        };
        0.5 * mu * speed * speed
    }
}

/// The harm test's numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct HarmRule {
    /// Per region, in [`Region::ALL`] order.
    pub limits: [RegionLimit; 12],
    /// A sharp or hot hazard: any touch harms.
    pub any_touch_harms: bool,
    /// Steps a window runs after the touch that opened it.
    pub window_steps: u32,
    /// The window's length (s): the sustained force is its impulse over this.
    pub window_s: f64,
}

impl HarmRule {
    /// The rule of a scene: its label thresholds (`configs/labels.toml`, stored in every
    /// spec) and its hazard's true flags (`sharp`, `hot`).
    pub fn of_labels(l: &LabelConfig, hazard_flags: &[String], dt: f64) -> Self {
        let limits = Region::ALL.map(|r| {
            let limit = l
                .harm
                .get(r.name())
                .unwrap_or_else(|| panic!("labels.harm.{} is missing (validated)", r.name()));
            RegionLimit::of(limit, l.harm_transient_factor)
        });
        let window_steps = (l.strike_window_s / dt).round() as u32;
        HarmRule {
            limits,
            any_touch_harms: hazard_flags.iter().any(|f| f == "sharp" || f == "hot"),
            window_steps,
            window_s: window_steps as f64 * dt,
        }
    }

    /// The worst region of a window and how far it is over its limits.
    pub fn judge(&self, w: &StrikeWindow) -> Verdict {
        let mut worst: Option<Verdict> = None;
        for r in Region::ALL {
            let i = r.index();
            if !w.touched[i] {
                continue;
            }
            let limit = &self.limits[i];
            let force = w.region_impulse[i] / self.window_s;
            let ratio = (w.region_energy[i] / limit.energy_max).max(force / limit.force_max);
            if worst.as_ref().is_none_or(|v| ratio > v.ratio) {
                worst = Some(Verdict {
                    region: r,
                    energy: w.region_energy[i],
                    force,
                    ratio,
                    harm: false,
                });
            }
        }
        let mut v = worst.unwrap_or(Verdict {
            region: Region::Pelvis,
            energy: 0.0,
            force: 0.0,
            ratio: 0.0,
            harm: false,
        });
        // A sharp or hot hazard harms once it really presses on the body (a contact
        // within the solver's prediction distance carries no impulse yet).
        v.harm = v.ratio >= 1.0 || (self.any_touch_harms && w.impulse > 0.0);
        v
    }
}

/// A window's verdict: its worst region, that region's largest transient energy (J) and
/// sustained force (N), their larger ratio to the region's limits, and whether it harms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Verdict {
    pub region: Region,
    pub energy: f64,
    pub force: f64,
    pub ratio: f64,
    pub harm: bool,
}

/// One link touched by the hazard at one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Touch {
    /// Index of the link in [`Part::ALL`].
    pub part: usize,
    pub region: Region,
    /// Speed of the hazard's contact point relative to the link (m/s).
    pub speed: f64,
    /// The same along the contact normal, approaching (m/s, ≥ 0).
    pub normal_speed: f64,
    /// The hazard's effective mass at the contact point along the normal (kg).
    pub mass: f64,
    /// Normal impulse the link received this step (N·s).
    pub impulse: f64,
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
    /// Per region ([`Region::ALL`] order): touched at all, the largest transient energy
    /// of a touch (J), the total impulse (N·s).
    pub touched: [bool; 12],
    pub region_energy: [f64; 12],
    pub region_impulse: [f64; 12],
}

impl StrikeWindow {
    pub fn new(start: u32, parts: usize) -> Self {
        StrikeWindow {
            start,
            speed: 0.0,
            impulse: 0.0,
            per_part: vec![0.0; parts],
            touched: [false; 12],
            region_energy: [0.0; 12],
            region_impulse: [0.0; 12],
        }
    }

    /// Adds one step's touches, with the energies under `rule`.
    pub fn add(&mut self, rule: &HarmRule, touches: &[Touch]) {
        for t in touches {
            let i = t.region.index();
            self.speed = self.speed.max(t.speed);
            self.touched[i] = true;
            // Only a contact that pushes (an impulse) brings energy: one within the
            // solver's prediction distance may still miss.
            if t.impulse > 0.0 {
                let e = rule.limits[i].energy(t.mass, t.normal_speed);
                self.region_energy[i] = self.region_energy[i].max(e);
            }
            self.region_impulse[i] += t.impulse;
            if let Some(acc) = self.per_part.get_mut(t.part) {
                *acc += t.impulse;
            }
            self.impulse += t.impulse;
        }
    }

    /// Adds impulses only (no touch judged): the executor's catching hands.
    pub fn add_impulses(&mut self, impulses: &[f64]) {
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

/// Follows the harm test over a run, one call per physics step.
#[derive(Debug, Clone)]
pub struct StrikeMonitor {
    rule: HarmRule,
    parts: usize,
    open: Option<StrikeWindow>,
    first: Option<StrikeWindow>,
    strike: Option<StrikeWindow>,
    first_touch: Option<u32>,
}

impl StrikeMonitor {
    pub fn new(rule: HarmRule, parts: usize) -> Self {
        StrikeMonitor {
            rule,
            parts,
            open: None,
            first: None,
            strike: None,
            first_touch: None,
        }
    }

    pub fn rule(&self) -> &HarmRule {
        &self.rule
    }

    /// One step: the hazard's touches of the body's links this step (none: no touch).
    pub fn step(&mut self, step: u32, touches: &[Touch]) {
        let touch = !touches.is_empty();
        if touch && self.first_touch.is_none() {
            self.first_touch = Some(step);
        }
        if let Some(s) = self.strike.as_mut() {
            // Harm: its window is followed to its end, nothing after.
            if step <= s.start + self.rule.window_steps {
                s.add(&self.rule, touches);
            }
            return;
        }
        if self.open.is_none() && touch {
            self.open = Some(StrikeWindow::new(step, self.parts));
        }
        let Some(w) = self.open.as_mut() else {
            return;
        };
        w.add(&self.rule, touches);
        if self.rule.judge(w).harm {
            self.strike = self.open.take();
        } else if step >= w.start + self.rule.window_steps {
            let closed = self.open.take();
            if self.first.is_none() {
                self.first = closed;
            }
        }
    }

    /// The harming window, once the test has passed.
    pub fn strike(&self) -> Option<&StrikeWindow> {
        self.strike.as_ref()
    }

    /// A harming window that is over at `step` (the counterfactual run may stop).
    pub fn strike_over(&self, step: u32) -> bool {
        self.strike
            .as_ref()
            .is_some_and(|s| step >= s.start + self.rule.window_steps)
    }

    /// Whether a window is being followed (no verdict yet).
    pub fn window_open(&self) -> bool {
        self.open.is_some()
    }

    /// What the run records: the harming window, else the first window (closed, or still
    /// open when the run ended), else `None` (the hazard never touched the body).
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

/// The hazard's touch of the body link `other` (of `part`, shape `shape`) this step,
/// before `impulse` is known: the contact point `p` (the hazard's deepest, or nearest,
/// point against the link now; its centre of mass should the query find none), the speed
/// there relative to the link `v + ω × (p − c)` with the hazard's velocities of the step
/// before (`linvel`, `angvel`: before the contact impulse) minus the link's own velocity
/// at `p` (zero for the standing body's fixed links), its component along the contact
/// normal, the hazard's effective mass along that normal at `p`
/// (`1 / (1/m + (r × n)·I⁻¹(r × n))`, the free body's), and the region `p` lies in.
pub fn touch_at(
    world: &PhysicsWorld,
    hazard: ColliderHandle,
    (linvel, angvel): (Vector, Vector),
    other: ColliderHandle,
    part: Part,
    shape: LinkShape,
) -> Touch {
    let (h, o) = (&world.colliders[hazard], &world.colliders[other]);
    let body = h.parent().map(|b| &world.bodies[b]);
    let com = body.map_or(h.position().translation, |b| b.center_of_mass());
    let contact =
        rapier3d::parry::query::contact(h.position(), h.shape(), o.position(), o.shape(), 0.1);
    let (point, normal) = match contact {
        Ok(Some(c)) => (c.point1, Some(c.normal1)),
        _ => (com, None),
    };
    let v = linvel + angvel.cross(point - com);
    let link = o
        .parent()
        .map_or(Vector::ZERO, |b| world.bodies[b].velocity_at_point(point));
    let rel = v - link;
    let speed = rel.length() as f64;
    let (normal_speed, mass) = match (normal, body) {
        (Some(n), Some(b)) => (
            (rel.dot(n) as f64).max(0.0),
            effective_mass(b, point - com, n),
        ),
        (Some(n), None) => ((rel.dot(n) as f64).max(0.0), f64::INFINITY),
        (None, b) => (speed, b.map_or(f64::INFINITY, |b| b.mass() as f64)),
    };
    let local = o.position().inverse_transform_point(point);
    Touch {
        part: part as usize,
        region: Region::of(part, shape, [local.x, local.y, local.z].map(f64::from)),
        speed,
        normal_speed,
        mass,
        impulse: 0.0,
    }
}

/// Effective mass of a free rigid body along the unit direction `n` at the point `r` from
/// its centre of mass: `1 / (1/m + (r × n)·I⁻¹(r × n))` (infinite for an immovable one).
fn effective_mass(body: &RigidBody, r: Vector, n: Vector) -> f64 {
    let mp = &body.mass_properties().local_mprops;
    let rn = body.rotation().inverse() * r.cross(n);
    let inv_i = mp.reconstruct_inverse_inertia_matrix();
    let inv = mp.inv_mass as f64 + rn.dot(inv_i * rn) as f64;
    if inv > 0.0 {
        1.0 / inv
    } else {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule(sharp: bool) -> HarmRule {
        let l = crate::spec::LabelConfig::embedded();
        let flags = if sharp {
            vec!["sharp".to_string()]
        } else {
            vec![]
        };
        HarmRule::of_labels(&l, &flags, 1.0 / 240.0)
    }

    fn touch(part: Part, region: Region, speed: f64, mass: f64, impulse: f64) -> Touch {
        Touch {
            part: part as usize,
            region,
            speed,
            normal_speed: speed,
            mass,
            impulse,
        }
    }

    #[test]
    fn the_limits_are_iso_ts_15066_annex_a_transient_values() {
        let r = rule(false);
        assert_eq!(r.window_steps, 60);
        // Skull: F 130 N, k 150 N/mm, transient ×2: (260 N)² / (2 · 150 000 N/m).
        let skull = r.limits[Region::SkullForehead.index()];
        assert!((skull.energy_max - 260.0f64.powi(2) / 300_000.0).abs() < 1e-12);
        // Chest: 280² / 50 000 = 1.568 J; lower leg 260² / 120 000 = 0.563 J.
        assert!((r.limits[Region::Chest.index()].energy_max - 1.568).abs() < 1e-9);
        let leg = r.limits[Region::LowerLeg.index()];
        assert!((leg.energy_max - 260.0f64.powi(2) / 120_000.0).abs() < 1e-9);
        assert_eq!((leg.force_max, leg.body_mass), (130.0, 75.0));
    }

    #[test]
    fn a_window_harms_by_energy_by_sustained_force_or_by_a_sharp_touch() {
        let r = rule(false);
        let mut w = StrikeWindow::new(0, 13);
        // A 58 g ball at 1 m/s on the shin: ½ μ v² ≈ 0.029 J of 0.563 J.
        w.add(
            &r,
            &[touch(Part::LeftShank, Region::LowerLeg, 1.0, 0.058, 0.06)],
        );
        let v = r.judge(&w);
        assert!(!v.harm && v.region == Region::LowerLeg, "{v:?}");
        let mu = 0.058 * 75.0 / 75.058;
        assert!((v.energy - 0.5 * mu).abs() < 1e-12);
        // The same touch by a knife harms.
        assert!(rule(true).judge(&w).harm);
        // A steady 150 N on the shin over the window (> 130 N) harms however slowly.
        let mut push = StrikeWindow::new(0, 13);
        for _ in 0..=60 {
            let t = touch(Part::LeftShank, Region::LowerLeg, 0.01, 50.0, 150.0 / 240.0);
            push.add(&r, &[t]);
        }
        let v = r.judge(&push);
        assert!(
            v.harm && (v.force - 150.0 * 61.0 / 60.0).abs() < 1e-9,
            "{v:?}"
        );
        // The worst region is reported: a graze of the hand and a blow to the head.
        let mut two = StrikeWindow::new(0, 13);
        two.add(
            &r,
            &[
                touch(Part::LeftHand, Region::Hand, 0.2, 1.0, 0.1),
                touch(Part::Head, Region::SkullForehead, 4.4, 1.0, 4.0),
            ],
        );
        let v = r.judge(&two);
        assert!(v.harm && v.region == Region::SkullForehead && v.ratio > 30.0);
    }

    #[test]
    fn a_graze_then_a_blow_harms_on_the_blow_and_its_window_is_whole() {
        let mut m = StrikeMonitor::new(rule(false), 13);
        let graze = touch(Part::Torso, Region::Chest, 0.2, 1.0, 0.01);
        let blow = |impulse| touch(Part::Torso, Region::Chest, 3.0, 1.0, impulse);
        // A slow graze at step 10: no harm; its window closes at step 70.
        m.step(10, &[graze]);
        for k in 11..=70 {
            m.step(k, &[]);
        }
        assert!(!m.window_open() && m.strike().is_none());
        assert_eq!(m.report().unwrap().start, 10);
        // A 1 kg blow at 3 m/s (½ · 0.976 · 9 = 4.4 J > 1.57 J) at step 100: harm at
        // once; followed to step 160.
        m.step(100, &[blow(0.2)]);
        assert_eq!(m.strike().unwrap().start, 100);
        assert!(!m.strike_over(159));
        m.step(130, &[blow(0.3)]);
        m.step(161, &[blow(5.0)]);
        assert!(m.strike_over(160));
        let s = m.report().unwrap();
        assert_eq!((s.start, s.speed, s.heaviest_part()), (100, 3.0, 1));
        assert!((s.impulse - 0.5).abs() < 1e-12);
        assert_eq!(m.first_touch(), Some(10));
    }

    #[test]
    fn the_head_and_the_torso_are_split_into_regions() {
        let head = LinkShape::Sphere(0.10);
        assert_eq!(
            Region::of(Part::Head, head, [0.0, 0.0, 0.1]),
            Region::SkullForehead
        );
        assert_eq!(Region::of(Part::Head, head, [0.09, 0.0, 0.0]), Region::Face);
        assert_eq!(
            Region::of(Part::Head, head, [0.0, 0.0, -0.08]),
            Region::Neck
        );
        let torso = LinkShape::Box([0.09, 0.14, 0.15]);
        assert_eq!(
            Region::of(Part::Torso, torso, [0.09, 0.0, 0.05]),
            Region::Chest
        );
        assert_eq!(
            Region::of(Part::Torso, torso, [0.09, 0.0, -0.05]),
            Region::Abdomen
        );
        assert_eq!(
            Region::of(Part::Torso, torso, [-0.09, 0.0, 0.0]),
            Region::BackShoulders
        );
        assert_eq!(
            Region::of(Part::Torso, torso, [0.09, 0.1, 0.14]),
            Region::BackShoulders
        );
        assert_eq!(
            Region::of(Part::LeftShank, LinkShape::Sphere(0.05), [0.0; 3]),
            Region::LowerLeg
        );
    }
}
