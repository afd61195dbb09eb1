//! The body pose the 3D view shows: until simulated poses arrive from the render
//! pipeline, the pose inverse kinematics gives for the composed target tips at the
//! playhead (damped least squares, seed 000 eq. 3), warm-started from the last pose shown
//! and pulled toward a ready posture, recomputed only when the time or composition changes.

use crate::body::ik::{IkParams, solve};
use crate::body::sim::Motion;
use crate::body::skeleton::{Joint, Pose, REST, Skeleton};
use crate::kit::Side;
use crate::motion::compose::Composition;
use crate::render::Rendering;
use glam::{DQuat, DVec3};
use std::sync::Arc;

/// A simulated performance for the viewport: body poses and stick tips sampled at a fixed
/// rate, read in place from the render pipeline's output (or given whole, through
/// [`super::EditorApp::set_simulation`]).
#[derive(Clone, Debug)]
pub struct Simulated {
    /// Time of sample 0, s.
    pub start_s: f64,
    source: Source,
}

#[derive(Clone, Debug)]
enum Source {
    Motion(Motion),
    Rendering(Arc<Rendering>),
}

impl Simulated {
    /// `motion` with its sample 0 at `start_s` seconds.
    pub fn of_motion(start_s: f64, motion: Motion) -> Simulated {
        Simulated {
            start_s,
            source: Source::Motion(motion),
        }
    }

    /// A rendering's motion (not copied).
    pub fn of_rendering(rendering: Arc<Rendering>) -> Simulated {
        Simulated {
            start_s: rendering.start_s,
            source: Source::Rendering(rendering),
        }
    }

    /// The poses and tips, at the task rate.
    pub fn motion(&self) -> &Motion {
        match &self.source {
            Source::Motion(m) => m,
            Source::Rendering(r) => &r.motion,
        }
    }

    /// The rendering it comes from, if any: its drums recorded the membranes' motion.
    pub fn rendering(&self) -> Option<&Rendering> {
        match &self.source {
            Source::Motion(_) => None,
            Source::Rendering(r) => Some(r),
        }
    }

    /// The pose at `t_s` (nearest sample, clamped), if there are any.
    pub fn pose_at(&self, t_s: f64) -> Option<&Pose> {
        let m = self.motion();
        let last = m.poses.len().checked_sub(1)?;
        let k = ((t_s - self.start_s) * m.rate_hz).round().max(0.0) as usize;
        m.poses.get(k.min(last))
    }
}

/// The most ghost poses shown at once.
pub const MAX_GHOSTS: usize = 12;

/// The simulated poses at the impacts of the `selected` beats (each beat's first stroke;
/// at most [`MAX_GHOSTS`], the earliest), for the 3D view to show faintly.
pub fn ghosts(
    comp: &Composition,
    simulated: &Simulated,
    selected: &std::collections::BTreeSet<usize>,
) -> Vec<Pose> {
    selected
        .iter()
        .filter_map(|&b| comp.strokes.iter().find(|s| s.beat == b))
        .take(MAX_GHOSTS)
        .filter_map(|s| simulated.pose_at(s.time_s).copied())
        .collect()
}

/// A playing posture: upper arms forward, elbows bent, sticks pointing forward and down.
pub fn ready_pose() -> Pose {
    let mut p = REST;
    for side in [Side::Left, Side::Right] {
        let [shoulder, elbow, wrist, _] = Joint::arm(side);
        p[shoulder.index()] = DQuat::from_rotation_x(0.45);
        p[elbow.index()] = DQuat::from_rotation_x(1.1);
        p[wrist.index()] = DQuat::from_rotation_x(0.2);
    }
    p
}

/// Both tips of `comp` at time `t_s` (linear between samples, clamped to its ends), m.
pub fn tips_at(comp: &Composition, t_s: f64) -> Option<[DVec3; 2]> {
    if comp.is_empty() {
        return None;
    }
    let f = ((t_s - comp.start_s) * comp.rate_hz).clamp(0.0, (comp.len() - 1) as f64);
    let k = f.floor() as usize;
    let k1 = (k + 1).min(comp.len() - 1);
    let x = f - k as f64;
    Some([0, 1].map(|h| comp.tips[h][k].lerp(comp.tips[h][k1], x)))
}

/// The IK pose cache.
pub struct IkPose {
    key: Option<(u64, u64)>,
    pose: Pose,
    params: IkParams,
}

impl Default for IkPose {
    fn default() -> Self {
        IkPose {
            key: None,
            pose: ready_pose(),
            params: IkParams {
                max_iterations: 60,
                tolerance_m: 1e-4,
                ..IkParams::default()
            },
        }
    }
}

impl IkPose {
    /// The pose reaching `comp`'s tips at `t_s` (composition `generation` identifies it).
    pub fn pose(
        &mut self,
        skeleton: &Skeleton,
        comp: &Composition,
        generation: u64,
        t_s: f64,
    ) -> &Pose {
        let key = (generation, t_s.to_bits());
        if self.key == Some(key) {
            return &self.pose;
        }
        self.key = Some(key);
        if let Some(tips) = tips_at(comp, t_s) {
            let ready = ready_pose();
            for (h, side) in [Side::Left, Side::Right].into_iter().enumerate() {
                let r = solve(
                    skeleton,
                    &self.pose,
                    side,
                    tips[h],
                    Some(&ready),
                    &self.params,
                    &crate::body::limits::NO_LIMITS,
                );
                self.pose = r.pose;
            }
        }
        &self.pose
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A simulated pose is looked up by time, clamped to the take.
    #[test]
    fn simulated_pose_lookup() {
        let mut second = REST;
        second[0] = DQuat::from_rotation_z(0.1);
        let motion = |poses: Vec<Pose>| Motion::new(10.0, Default::default(), poses);
        let sim = Simulated::of_motion(1.0, motion(vec![REST, second]));
        assert_eq!(sim.pose_at(0.0), Some(&REST));
        assert_eq!(sim.pose_at(1.08), Some(&second));
        assert_eq!(sim.pose_at(50.0), Some(&second));
        assert!(
            Simulated::of_motion(0.0, motion(vec![]))
                .pose_at(1.0)
                .is_none()
        );
    }

    /// In the ready pose the sticks are in front of the body, below the shoulders.
    #[test]
    fn ready_pose_reaches_forward() {
        let s = Skeleton::default();
        let f = s.forward(&ready_pose());
        for side in [Side::Left, Side::Right] {
            let tip = f.tip(side);
            assert!(tip.y > 0.3, "{tip}");
            assert!(tip.z < f.position[Joint::arm(side)[0].index()].z);
        }
    }

    /// Ghosts are the simulated poses at the selected beats' first strokes, in beat
    /// order; unselected beats and beats without strokes have none.
    #[test]
    fn ghosts_at_the_selected_impacts() {
        let poses: Vec<Pose> = (0..20)
            .map(|k| {
                let mut p = REST;
                p[0] = DQuat::from_rotation_z(0.01 * k as f64);
                p
            })
            .collect();
        let sim = Simulated::of_motion(0.0, Motion::new(10.0, Default::default(), poses.clone()));
        let stroke = |beat: usize, time_s: f64| crate::motion::plan::PlannedStroke {
            beat,
            tick: 0,
            hand: Side::Right,
            time_s,
            target: DVec3::ZERO,
            toward_player: DVec3::NEG_Y,
            drum: 0,
            mode: crate::score::PlayingMode::Legato,
            dynamic: crate::score::Dynamic::Mf,
            unit: 0,
        };
        let comp = Composition {
            rate_hz: 10.0,
            start_s: 0.0,
            tips: [vec![DVec3::ZERO; 20], vec![DVec3::ZERO; 20]],
            tags: Default::default(),
            strokes: vec![stroke(0, 0.5), stroke(1, 1.2), stroke(1, 1.4)],
            impact_samples: vec![5, 12, 14],
            limits: crate::body::limits::NO_LIMITS,
            muffles: Default::default(),
        };
        let selected = [1, 0, 7].into_iter().collect();
        assert_eq!(ghosts(&comp, &sim, &selected), vec![poses[5], poses[12]]);
        assert!(ghosts(&comp, &sim, &Default::default()).is_empty());
    }
}
