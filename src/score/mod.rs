//! The gesture score: beats in exact musical time (integer ticks) under a tempo map and
//! time signatures, each with hand, playing mode, dynamic, drum, pitch, impact location and
//! an optional roll; read from and written to strict, versioned RON files (`scores/*.ron`),
//! with the editor's view of it (`view`: the 3D camera) when saved from the editor, and
//! where each beat stood in the file it was read from (`places`: messages name beats by
//! their number in the file and their line).

pub mod demos;
pub mod edit;
pub mod meter;
mod migrate;
pub mod places;
pub mod settings;
pub mod tempo;
pub mod tuning;
pub mod validate;
pub mod view;

use crate::base::pitch::Pitch;
use crate::base::ron_file::{self, FileError};
use crate::kit::{Kit, Side};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

pub use crate::base::gesture::{Dynamic, Grip, Hand, ImpactLocation, PlayingMode};
pub use meter::{BarBeat, MeterChange, MeterMap};
pub use places::BeatPlaces;
pub use settings::Settings;
pub use tempo::{TempoChange, TempoMap, TempoPoint};
pub use view::{SavedCamera, ViewSettings};

/// The score file format this timpanist writes and the newest it reads.
pub const SCORE_FORMAT_VERSION: u32 = 2;

/// Ticks per quarter note of new scores.
pub const DEFAULT_TICKS_PER_QUARTER: u32 = 960;

/// A roll (tremolo) starting at a beat: single strokes alternating hands, starting with
/// the beat's hand.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Roll {
    /// How long the roll lasts, ticks.
    pub length_ticks: u64,
    /// Strokes per quarter note (e.g. 8 for thirty-second notes).
    pub strokes_per_quarter: u32,
}

/// One stroke (or roll) of the score.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Beat {
    /// Position in ticks from the start of the score.
    pub tick: u64,
    pub hand: Hand,
    pub mode: PlayingMode,
    pub dynamic: Dynamic,
    /// Index of the drum in the kit (0 is the first drum of the kit file).
    pub drum: usize,
    /// The pitch the drum is tuned to for this beat (another than it plays just before is
    /// a pedal change: [`tuning`]); `None` plays the drum as it is tuned then.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pitch: Option<Pitch>,
    pub location: ImpactLocation,
    /// A roll starting at this beat; `None` for a single stroke.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roll: Option<Roll>,
    /// Secco: this many ticks after the beat's (last) stroke the player's hand touches the
    /// head and stops it ringing; `None` lets the drum ring (laissez vibrer).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damp: Option<u64>,
}

impl Beat {
    /// A plain stroke: legato, mf, at the playing spot, hand left to the sticking.
    pub fn plain(tick: u64, drum: usize) -> Beat {
        Beat {
            tick,
            hand: Hand::Auto,
            mode: PlayingMode::Legato,
            dynamic: Dynamic::Mf,
            drum,
            pitch: None,
            location: ImpactLocation::PlayingSpot,
            roll: None,
            damp: None,
        }
    }

    /// Tick at which the hand touches the head to stop it, if the beat is damped.
    pub fn damp_tick(&self) -> Option<u64> {
        self.damp.map(|d| self.end_tick() + d)
    }

    /// The beat's own pitch, else `kit`'s tuning of its drum (what a beat naming none
    /// sounds is the drum's pitch then: [`Score::sounding_pitches`]).
    pub fn sounding_pitch(&self, kit: &Kit) -> Pitch {
        self.pitch.unwrap_or(kit.drums[self.drum].tuning)
    }

    /// Ticks of the beat's strokes: the beat itself, or each stroke of its roll, one every
    /// quarter / strokes-per-quarter ticks from the beat up to (not at) the roll's end.
    pub fn stroke_ticks(&self, ticks_per_quarter: u32) -> impl Iterator<Item = u64> + use<> {
        let tick = self.tick;
        let (step, count) = match self.roll {
            None => (1, 1),
            Some(r) => {
                let step = u64::from(ticks_per_quarter / r.strokes_per_quarter.max(1)).max(1);
                (step, r.length_ticks.div_ceil(step).max(1))
            }
        };
        (0..count).map(move |k| tick + k * step)
    }

    /// Tick where the beat ends (the beat itself, or the end of its roll).
    pub fn end_tick(&self) -> u64 {
        self.tick + self.roll.map_or(0, |r| r.length_ticks)
    }
}

/// A user edit of one hand's tip trajectory: a smooth displacement around a moment, zero
/// outside `tick ± reach_ticks` (a cubic B-spline bump; impacts are never moved by it).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Handle {
    pub hand: Side,
    /// Centre of the edit, ticks.
    pub tick: u64,
    /// Half-width of its support, ticks.
    pub reach_ticks: u64,
    /// Displacement at the centre, m (performer frame: x right, y forward, z up).
    pub offset_m: [f64; 3],
}

/// Pins one stroke's impact to an exact point (instead of its drum's impact location).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImpactPin {
    pub hand: Side,
    /// The stroke's tick (a beat's, or one stroke of a roll).
    pub tick: u64,
    /// Where the stick tip meets the head, m (performer frame).
    pub point_m: [f64; 3],
}

/// A whole score, as saved in a `.ron` file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename = "Score", deny_unknown_fields)]
pub struct Score {
    /// File format version (currently 1).
    pub version: u32,
    pub title: String,
    /// The kit: a path ending in `.ron`, relative to the score file, or the name of a
    /// bundled kit ("standard", "pair").
    pub kit: String,
    pub grip: Grip,
    /// Resolution of musical time (960 in new scores).
    pub ticks_per_quarter: u32,
    /// Tempo points, the first at tick 0.
    pub tempo: Vec<TempoPoint>,
    /// Time signatures, the first at bar 1.
    pub meter: Vec<MeterChange>,
    /// The beats, in time order.
    pub beats: Vec<Beat>,
    /// Edits of the composed tip trajectories (format 2).
    pub handles: Vec<Handle>,
    /// Impact points pinned by the user (format 2).
    pub pins: Vec<ImpactPin>,
    /// How it is performed and heard (left out of the file when default).
    #[serde(default, skip_serializing_if = "Settings::is_default")]
    pub settings: Settings,
    /// How the editor last showed it (its 3D camera), written by the editor's Save.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub view: Option<ViewSettings>,
}

/// A score together with its kit, as loaded from disk.
#[derive(Clone, Debug)]
pub struct LoadedScore {
    pub score: Score,
    pub kit: Kit,
    /// Where the kit came from, for display.
    pub kit_source: String,
    /// Things the user should know that did not stop loading (e.g. a kit fallback).
    pub notices: Vec<String>,
}

impl Score {
    /// `kit` as this score plays it: the settings' drum changes applied, then each drum
    /// retuned to the pitch its beats name ([`tuning`]).
    pub fn kit<'k>(&self, kit: &'k Kit) -> std::borrow::Cow<'k, Kit> {
        tuning::tuned(self, self.settings.kit(kit))
    }

    /// The pedal changes this score asks of `kit` ([`tuning::pedal_changes`] of its
    /// [`kit`](Score::kit)), in time order.
    pub fn pedal_changes(&self, kit: &Kit) -> Vec<tuning::PedalChange> {
        tuning::pedal_changes(self, &self.settings.kit(kit))
    }

    /// [`Score::pedal_changes`], each naming its beat as `places` say it stands in the
    /// file the score was read from (for messages; the numbers are no longer indices).
    pub fn pedal_changes_placed(&self, kit: &Kit, places: &BeatPlaces) -> Vec<tuning::PedalChange> {
        (self.pedal_changes(kit).into_iter())
            .map(|c| tuning::PedalChange {
                beat: places.number(c.beat),
                ..c
            })
            .collect()
    }

    /// The pitch each beat sounds on `kit` ([`tuning::sounding_pitches`] of its
    /// [`kit`](Score::kit)).
    pub fn sounding_pitches(&self, kit: &Kit) -> Vec<crate::base::pitch::Pitch> {
        tuning::sounding_pitches(self, &self.settings.kit(kit))
    }

    /// The retunings that carry out this score's pedal changes on `kit`, in time order.
    pub fn retunes(&self, kit: &Kit) -> Vec<crate::kit::Retune> {
        tuning::retunes(self, &self.settings.kit(kit))
    }

    /// An empty score in 4/4 at 100 bpm on the standard kit.
    pub fn new(title: &str) -> Score {
        Score {
            version: SCORE_FORMAT_VERSION,
            title: title.to_string(),
            kit: "standard".into(),
            grip: Grip::French,
            ticks_per_quarter: DEFAULT_TICKS_PER_QUARTER,
            tempo: vec![TempoPoint {
                tick: 0,
                bpm: 100.0,
                change: TempoChange::Step,
            }],
            meter: vec![MeterChange {
                bar: 1,
                numerator: 4,
                denominator: 4,
            }],
            beats: Vec::new(),
            handles: Vec::new(),
            pins: Vec::new(),
            settings: Settings::default(),
            view: None,
        }
    }

    /// Parse score text strictly (unknown or missing fields are errors), migrating older
    /// format versions; beats are put in time order. Does not check against a kit.
    pub fn parse(path: &Path, text: &str) -> Result<Score, FileError> {
        Score::parse_placed(path, text).map(|(score, _)| score)
    }

    /// [`Score::parse`], with where each beat stood in the text (its number in the file's
    /// list and its line and column), which messages about it name.
    pub fn parse_placed(path: &Path, text: &str) -> Result<(Score, BeatPlaces), FileError> {
        #[derive(Deserialize)]
        #[serde(rename = "Score")]
        struct Probe {
            version: u32,
        }
        let probe: Probe = ron_file::parse(path, text)?;
        let mut score: Score = match probe.version {
            1 => migrate::from_v1(ron_file::parse(path, text)?),
            2 => ron_file::parse(path, text)?,
            found => {
                return Err(ron_file::unsupported_version(
                    path,
                    found,
                    SCORE_FORMAT_VERSION,
                ));
            }
        };
        let places = BeatPlaces::sort(&mut score.beats, text);
        Ok((score, places))
    }

    /// Put beats in time order (stable, so simultaneous beats keep their file order).
    pub fn sort_beats(&mut self) {
        self.beats.sort_by_key(|b| b.tick);
    }

    /// Save atomically as pretty RON.
    pub fn save(&self, path: &Path) -> Result<(), FileError> {
        ron_file::save(path, self)
    }

    /// The score as RON text, exactly as [`Score::save`] writes it.
    pub fn to_ron(&self) -> String {
        ron_file::to_pretty(self)
    }

    /// The tempo map of this score.
    pub fn tempo_map(&self) -> TempoMap {
        TempoMap::new(&self.tempo, self.ticks_per_quarter)
    }

    /// The bar map of this score.
    pub fn meter_map(&self) -> MeterMap {
        MeterMap::new(&self.meter, self.ticks_per_quarter)
    }

    /// Seconds from the start to each beat.
    pub fn beat_times(&self) -> Vec<f64> {
        let map = self.tempo_map();
        self.beats
            .iter()
            .map(|b| map.seconds_at(b.tick as f64))
            .collect()
    }

    /// Length of the score in seconds (to its last stroke).
    pub fn duration_s(&self) -> f64 {
        let end = self.beats.iter().map(Beat::end_tick).max().unwrap_or(0);
        self.tempo_map().seconds_at(end as f64)
    }

    /// Find the kit this score refers to, relative to `score_path`'s folder.
    pub fn resolve_kit(&self, score_path: &Path) -> Result<(Kit, String, Vec<String>), FileError> {
        if !self.kit.ends_with(".ron") {
            return Kit::bundled(&self.kit)
                .map(|k| (k, format!("bundled kit \"{}\"", self.kit), Vec::new()))
                .ok_or_else(|| {
                    let names: Vec<&str> =
                        crate::kit::BUNDLED_KITS.iter().map(|(n, _)| *n).collect();
                    FileError::invalid(
                        score_path,
                        "kit",
                        format!(
                            "\"{}\" is neither a .ron path nor a bundled kit (bundled: {})",
                            self.kit,
                            names.join(", ")
                        ),
                    )
                });
        }
        let dir = score_path.parent().unwrap_or(Path::new("."));
        let kit_path: PathBuf = dir.join(&self.kit);
        if kit_path.exists() {
            let kit = Kit::load(&kit_path)?;
            return Ok((kit, kit_path.display().to_string(), Vec::new()));
        }
        // A score moved away from its kit folder still opens if the kit is a bundled one.
        let stem = Path::new(&self.kit)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("");
        match Kit::bundled(stem) {
            Some(kit) => Ok((
                kit,
                format!("bundled kit \"{stem}\""),
                vec![format!(
                    "kit file {} not found; using the bundled kit \"{stem}\"",
                    kit_path.display()
                )],
            )),
            None => Err(FileError::invalid(
                score_path,
                "kit",
                format!("kit file {} not found", kit_path.display()),
            )),
        }
    }

    /// Problems of this score against `kit`, in file order, its beats numbered as it
    /// holds them.
    pub fn problems(&self, kit: &Kit) -> Vec<crate::base::problem::Problem> {
        self.problems_placed(kit, &BeatPlaces::in_order())
    }

    /// Problems of this score against `kit`, in file order, its beats named as `places`
    /// says they stand in the file it was read from.
    pub fn problems_placed(
        &self,
        kit: &Kit,
        places: &BeatPlaces,
    ) -> Vec<crate::base::problem::Problem> {
        validate::problems(self, kit, places)
    }
}

impl LoadedScore {
    /// Parse score text (with `path` for errors and kit lookup), find its kit and check the
    /// score against it.
    pub fn parse(path: &Path, text: &str) -> Result<LoadedScore, FileError> {
        LoadedScore::parse_placed(path, text).map(|(loaded, _)| loaded)
    }

    /// [`LoadedScore::parse`], with where each beat stood in the text.
    pub fn parse_placed(path: &Path, text: &str) -> Result<(LoadedScore, BeatPlaces), FileError> {
        let (score, places) = Score::parse_placed(path, text)?;
        Ok((LoadedScore::checked(path, score, &places)?, places))
    }

    /// `score` (read from `path`, which names it in errors and places its kit) with its
    /// kit found and the score checked against it.
    pub fn from_score(path: &Path, score: Score) -> Result<LoadedScore, FileError> {
        LoadedScore::checked(path, score, &BeatPlaces::in_order())
    }

    /// [`LoadedScore::from_score`], a problem naming its beat as `places` say.
    fn checked(path: &Path, score: Score, places: &BeatPlaces) -> Result<LoadedScore, FileError> {
        let (kit, kit_source, notices) = score.resolve_kit(path)?;
        if let Some(p) = score.problems_placed(&kit, places).into_iter().next() {
            return Err(FileError::problem(path, p));
        }
        Ok(LoadedScore {
            score,
            kit,
            kit_source,
            notices,
        })
    }

    /// Load a score file with its kit, strictly.
    pub fn load(path: &Path) -> Result<LoadedScore, FileError> {
        LoadedScore::load_placed(path).map(|(loaded, _)| loaded)
    }

    /// [`LoadedScore::load`], with where each beat stood in the file.
    pub fn load_placed(path: &Path) -> Result<(LoadedScore, BeatPlaces), FileError> {
        LoadedScore::parse_placed(path, &ron_file::read_text(path)?)
    }
}
