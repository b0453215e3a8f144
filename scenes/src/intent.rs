//! Where a scene group's event is aimed (label rule v5, specification §6): at the hands, at the
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
    /// `heavy_mass_kg`), larger than the arms hold (`catch_radius_max`), or longer than
    /// the hands can meet at its centre (`hands_half_length_max`, `[aim]`: a half length
    /// beyond the arm's reach puts its ends into the head and chest of a body reaching
    /// for its middle); else at the hands.
    pub fn for_object(
        object: &Object,
        near_miss: bool,
        labels: &LabelConfig,
        hands_half_length_max: f64,
    ) -> Intent {
        let dangerous = object.has_hazard("sharp")
            || object.has_hazard("hot")
            || (object.has_hazard("fragile") && object.has_hazard("large"))
            || object.mass >= labels.heavy_mass_kg;
        let half_length = object.half_extents().into_iter().fold(0.0, f64::max);
        let too_large = (labels.catch_radius_max > 0.0
            && object.bounding_radius() > labels.catch_radius_max)
            || (hands_half_length_max > 0.0 && half_length > hands_half_length_max);
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

#[cfg(test)]
mod tests {
    use super::*;

    fn catalog_object(id: &str) -> Object {
        let catalog = rh_catalog::Catalog::embedded().unwrap();
        catalog.object(id).unwrap().clone()
    }

    #[test]
    fn a_benign_object_longer_than_the_hands_meet_is_aimed_at_the_body() {
        let config = crate::config::Config::embedded().unwrap();
        // The 1.1 m styrofoam TV (half length 0.55 m, bounding radius 0.64 m, inside
        // catch_radius_max 0.72): at the hands without the length limit, at the body
        // with it.
        let tv = catalog_object("styrofoam_tv");
        assert!(tv.bounding_radius() < 0.72);
        let l = &config.labels;
        assert_eq!(l.catch_radius_max, 0.72);
        assert_eq!(config.aim.hands_half_length_max, 0.5);
        assert_eq!(Intent::for_object(&tv, false, l, 0.0), Intent::Hands);
        assert_eq!(Intent::for_object(&tv, false, l, 0.5), Intent::Body);
        // The 0.9 m foam mirror (half length 0.45 m) stays at the hands.
        let mirror = catalog_object("foam_mirror");
        assert_eq!(Intent::for_object(&mirror, false, l, 0.5), Intent::Hands);
        // A near miss is a near miss whatever the length.
        assert_eq!(Intent::for_object(&tv, true, l, 0.5), Intent::Miss);
    }
}
