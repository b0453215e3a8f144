//! Where a scene group's event is aimed (label rule v5, SPEC §6): at the hands, at the
//! body, or (a deliberate near miss) beside the observer. Decided once per group by the
//! randomizer from the object's own properties and the near-miss draw, recorded in the
//! spec (`family_params.aim_intent`: 0 hands, 1 body, 2 miss), and read by the families
//! that aim their own event (a throw) and by `aim::aim_group` for the others.

use rh_catalog::Object;
use rh_physics::spec::{LabelConfig, SceneSpec};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Intent {
    /// A benign hazard that fits in the arms: its path passes in front of the chest at a
    /// height the hands can hold, after they can get there (a CATCH if not too fast).
    Hands,
    /// A dangerous hazard, or one too large to hold: its path runs into the body (a
    /// DODGE when the touch would harm).
    Body,
    /// A deliberate near miss (`build.far_observer_share`): beside the path, out of reach.
    Miss,
}

/// The `family_params` key the intent is recorded under.
pub const PARAM: &str = "aim_intent";

impl Intent {
    pub fn code(self) -> f64 {
        match self {
            Intent::Hands => 0.0,
            Intent::Body => 1.0,
            Intent::Miss => 2.0,
        }
    }

    /// A group's intent: a near miss when drawn so; else at the body when the object is
    /// dangerous by its properties (sharp, hot, large and fragile, or at least
    /// `heavy_mass_kg`) or larger than the arms hold (`catch_radius_max`); else at the
    /// hands.
    pub fn for_object(object: &Object, near_miss: bool, labels: &LabelConfig) -> Intent {
        let dangerous = object.has_hazard("sharp")
            || object.has_hazard("hot")
            || (object.has_hazard("fragile") && object.has_hazard("large"))
            || object.mass >= labels.heavy_mass_kg;
        let too_large =
            labels.catch_radius_max > 0.0 && object.bounding_radius() > labels.catch_radius_max;
        if near_miss {
            Intent::Miss
        } else if dangerous || too_large {
            Intent::Body
        } else {
            Intent::Hands
        }
    }

    /// The intent a spec records (`None` for specs from before label rule v5).
    pub fn of(spec: &SceneSpec) -> Option<Intent> {
        match spec.family_params.get(PARAM).copied() {
            Some(c) if c == 0.0 => Some(Intent::Hands),
            Some(c) if c == 1.0 => Some(Intent::Body),
            Some(c) if c == 2.0 => Some(Intent::Miss),
            _ => None,
        }
    }
}
