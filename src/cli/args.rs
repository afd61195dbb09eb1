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
arg_enum!(UpArg => UpAxis { Y => UpAxis::Y, Z => UpAxis::Z });

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
arg_enum!(SoundArg => crate::sound::SoundModel {
    Modal => crate::sound::SoundModel::Modal,
    Sample => crate::sound::SoundModel::Sample,
    Signal => crate::sound::SoundModel::Signal,
});
