//! Stems per hand: what each stick's contacts make the kit sound, panned and scaled as
//! in the mix, so the two sum to the mix to the rounding. Every model is linear in the
//! contacts once the head's tuning is fixed: the sample and signal models replay each
//! contact on its own (rendered from one hand's record, damped where the whole record
//! has hands resting); the modal model's pitch glide depends on everything ringing on
//! the head, so each hand's share rings in banks retuned with the whole head's glide
//! (`modal::resynthesise` with hands), and the sympathetic ringing of the other heads is
//! driven by each hand's share.

use super::modal::{self, DrumSynth, SoundHeads};
use super::{Audio, SoundError, SoundModel, Touch, Voicing, calibration, room, sympathy};
use crate::drum::DrumSet;
use crate::kit::{Kit, Side};

/// The sound of the left and the right stick (stereo, 48 kHz, the mix's gain), in that
/// order, of what `drums` recorded with hands resting at `touches`, `duration_s` long.
pub fn hand_stems(
    kit: &Kit,
    (drums, touches): (&DrumSet, &[Touch]),
    duration_s: f64,
    voicing: impl Into<Voicing>,
) -> Result<[Audio; 2], SoundError> {
    let voicing = voicing.into();
    let model = voicing.model;
    let (mix, _) = super::render_touched(kit, drums, touches, duration_s, voicing, None)?;
    let frames = mix.frames();
    let calibration = calibration::Calibration::shipped();
    // Per hand, per drum: the drum's synthesis of that hand's contacts.
    let mut monos: [Vec<Vec<f32>>; 2] = Default::default();
    let mut heads: SoundHeads = Vec::new();
    let resting: Vec<Vec<(f64, f64)>> = (0..kit.drums.len())
        .map(|j| super::touches_of(touches, drums, j))
        .collect();
    for (j, own) in resting.iter().enumerate() {
        if model == SoundModel::Modal {
            let tunings = modal::sound_heads(kit, drums, j, calibration);
            let mut hands: [Vec<f32>; 2] = Default::default();
            modal::resynthesise(
                &tunings,
                (drums, own),
                j,
                (&mut Vec::new(), Some(&mut hands)),
                frames,
                &mut DrumSynth::default(),
            );
            heads.push(tunings);
            for (m, h) in monos.iter_mut().zip(hands) {
                m.push(h);
            }
            continue;
        }
        for side in [Side::Left, Side::Right] {
            let alone = drums.only_side(side);
            let mut mono = vec![0.0; frames];
            if model == SoundModel::Sample {
                super::sample::render_drum(kit, (&alone, own), j, &mut mono)?;
            } else {
                super::signal::render_drum((&alone, own), j, &mut mono);
            }
            monos[modal::side_index(side)].push(mono);
        }
    }
    Ok(monos.map(|monos| {
        let sympathies: Vec<Vec<f32>> = if model == SoundModel::Modal {
            let refs: Vec<&[f32]> = monos.iter().map(Vec::as_slice).collect();
            let fresh = vec![0; refs.len()];
            (resting.iter().enumerate())
                .map(|(j, own)| {
                    let mut state = sympathy::SympathyState::default();
                    let heard = (&heads, &own[..]);
                    sympathy::resynthesise(kit, heard, j, (&refs, &fresh), frames, &mut state);
                    state.out
                })
                .collect()
        } else {
            Vec::new()
        };
        let mut samples = vec![0.0f32; 2 * frames];
        for (j, (drum, mono)) in kit.drums.iter().zip(&monos).enumerate() {
            let sympathy = sympathies.get(j).map(Vec::as_slice);
            // Dry: the hand's stem is heard in the room once summed.
            let stem = super::stem(drum, model.into(), (mono, sympathy), mix.gain);
            for (s, x) in samples.iter_mut().zip(stem.samples.iter()) {
                *s += x;
            }
        }
        room::reverberate(voicing.room, &mut samples);
        Audio {
            samples: samples.into(),
            ..mix.clone()
        }
    }))
}
