//! Command-line spellings of the library's enums and small value parsers.

use crate::kit::Side;
use crate::mocap::import::Format;
use crate::mocap::ingest::UpAxis;
use crate::score::{Dynamic, Grip, ImpactLocation, PlayingMode};
use clap::ValueEnum;

/// Map a command-line enum onto a library enum, one variant to one variant.
macro_rules! arg_enum {
    ($arg:ident => $lib:ty { $($variant:ident => $value:expr),+ $(,)? }) => {
        #[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
        pub enum $arg { $($variant),+ }
        impl From<$arg> for $lib {
            fn from(a: $arg) -> $lib {
                match a { $($arg::$variant => $value),+ }
            }
        }
    };
}

arg_enum!(ModeArg => PlayingMode {
    Legato => PlayingMode::Legato,
    Tenuto => PlayingMode::Tenuto,
    Accent => PlayingMode::Accent,
    VerticalAccent => PlayingMode::VerticalAccent,
    Staccato => PlayingMode::Staccato,
});
arg_enum!(LocationArg => ImpactLocation {
    Centre => ImpactLocation::Centre,
    PlayingSpot => ImpactLocation::PlayingSpot,
    Rim => ImpactLocation::Rim,
});
arg_enum!(SideArg => Side { Left => Side::Left, Right => Side::Right });
arg_enum!(DynamicArg => Dynamic {
    Pp => Dynamic::Pp,
    P => Dynamic::P,
    Mp => Dynamic::Mp,
    Mf => Dynamic::Mf,
    F => Dynamic::F,
    Ff => Dynamic::Ff,
});
arg_enum!(GripArg => Grip { French => Grip::French, German => Grip::German });
arg_enum!(UpArg => UpAxis {
    X => UpAxis::X,
    Y => UpAxis::Y,
    Z => UpAxis::Z,
    NegX => UpAxis::NegX,
    NegY => UpAxis::NegY,
    NegZ => UpAxis::NegZ,
});

/// A capture format by name (c3d, motive, vicon, trc, csv).
pub fn parse_format(s: &str) -> Result<Format, String> {
    Format::from_name(s)
        .ok_or_else(|| format!("unknown format \"{s}\": expected c3d, motive, vicon, trc or csv"))
}

/// `--tips`: "LEFT,RIGHT", "LEFT," or ",RIGHT", or one label.
pub fn parse_tips(s: &str) -> Result<crate::cli::mocap::TipsArg, String> {
    use crate::cli::mocap::TipsArg;
    let label = |x: &str| Some(x.trim().to_string()).filter(|x| !x.is_empty());
    match s.split_once(',') {
        None => label(s)
            .map(TipsArg::One)
            .ok_or_else(|| "--tips: expected a label".to_string()),
        Some((a, b)) => match (label(a), label(b)) {
            (None, None) => Err(format!("expected LEFT,RIGHT labels, found \"{s}\"")),
            (l, r) => Ok(TipsArg::Both(l, r)),
        },
    }
}

/// `--tip-past`: a distance in metres, 0–0.5.
pub fn parse_tip_past(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(d) if (0.0..=0.5).contains(&d) => Ok(d),
        _ => Err(format!(
            "expected the tip's distance past the first marker, 0–0.5 metres, found \"{s}\""
        )),
    }
}

/// Three comma-separated numbers.
pub fn parse_vec3(s: &str) -> Result<glam::DVec3, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("\"{s}\": {e}"))?;
    match v.as_slice() {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(glam::DVec3::new(*x, *y, *z)),
        _ => Err(format!("expected x,y,z in metres, found \"{s}\"")),
    }
}
arg_enum!(ControlArg => crate::body::sim::Pipeline {
    Himc => crate::body::sim::Pipeline::Himc,
    Id => crate::body::sim::Pipeline::Id,
    Ik => crate::body::sim::Pipeline::Ik,
});
arg_enum!(LevelsArg => crate::transcribe::Levels {
    Absolute => crate::transcribe::Levels::Absolute,
    Relative => crate::transcribe::Levels::Relative,
});
arg_enum!(SoundArg => crate::sound::SoundModel {
    Modal => crate::sound::SoundModel::Modal,
    Sample => crate::sound::SoundModel::Sample,
    Signal => crate::sound::SoundModel::Signal,
});

arg_enum!(RoomArg => crate::sound::Room {
    Dry => crate::sound::Room::Dry,
    Studio => crate::sound::Room::Studio,
    Hall => crate::sound::Room::Hall,
});

/// `render --video-fps`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum VideoFpsArg {
    #[value(name = "30")]
    Fps30,
    #[value(name = "60")]
    Fps60,
}

impl VideoFpsArg {
    /// Frames per second.
    pub fn fps(self) -> u32 {
        match self {
            VideoFpsArg::Fps30 => 30,
            VideoFpsArg::Fps60 => 60,
        }
    }
}

/// `render --video-camera`: the editor's default camera or a named view.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum VideoCameraArg {
    /// The editor's default camera (in front, to the right, above).
    Editor,
    /// Over the player's shoulder.
    Player,
    Front,
    Side,
    Top,
}

impl VideoCameraArg {
    /// The camera.
    pub fn camera(self) -> crate::scene::camera::Camera {
        use crate::scene::camera::{Camera, View};
        match self {
            VideoCameraArg::Editor => Camera::default(),
            VideoCameraArg::Player => Camera::of_view(View::Player),
            VideoCameraArg::Front => Camera::of_view(View::Front),
            VideoCameraArg::Side => Camera::of_view(View::Side),
            VideoCameraArg::Top => Camera::of_view(View::Top),
        }
    }
}

/// `render --bvh-rate`: the task rate or a video rate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BvhRateArg {
    /// Every task sample (250 Hz).
    #[value(name = "250")]
    Task,
    #[value(name = "120")]
    Hz120,
    #[value(name = "60")]
    Hz60,
}

impl BvhRateArg {
    /// Frames per second, `None` for the motion's own rate.
    pub fn hz(self) -> Option<f64> {
        match self {
            BvhRateArg::Task => None,
            BvhRateArg::Hz120 => Some(120.0),
            BvhRateArg::Hz60 => Some(60.0),
        }
    }
}

arg_enum!(BvhUnitsArg => crate::io::bvh::Units {
    M => crate::io::bvh::Units::Metres,
    Cm => crate::io::bvh::Units::Centimetres,
});

/// `render --wav-format`: the WAVs' sample format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum WavFormatArg {
    /// 16-bit integer PCM.
    #[value(name = "16")]
    Pcm16,
    /// 24-bit integer PCM.
    #[value(name = "24")]
    Pcm24,
    /// 32-bit float.
    #[value(name = "f32")]
    Float32,
}

impl From<WavFormatArg> for crate::sound::WavFormat {
    fn from(a: WavFormatArg) -> Self {
        match a {
            WavFormatArg::Pcm16 => crate::sound::WavFormat::Pcm16,
            WavFormatArg::Pcm24 => crate::sound::WavFormat::Pcm24,
            WavFormatArg::Float32 => crate::sound::WavFormat::Float32,
        }
    }
}
