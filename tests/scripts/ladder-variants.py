#!/usr/bin/env python3
"""Write the dynamics ladder (scores/dynamics-ladder.ron) moved to other drums, pitches,
tempos and hands: the ladders the strokes were measured on (README "Strokes, measured").

    tests/scripts/ladder-variants.py OUT_DIR
    for s in OUT_DIR/*.ron; do timpanist render "$s" --wav /tmp/x.wav --events "${s%.ron}.json" --stats; done

Each variant puts the ladder's right-hand strokes (on the 26-inch drum) and left-hand
strokes (on the 29-inch) on another drum each, optionally at a pitch (a pedal setting
within the drum's range), at another tempo, and with the hands swapped. Two of them cross
the body and are refused as out of reach, naming the beat.
"""
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
# name: (right-hand strokes' (drum, pitch), left-hand strokes' (drum, pitch), bpm, swap)
VARIANTS = {
    "d2f2": ((1, "F2"), (0, "D2"), 100, False),
    "b32_29": ((1, "F2"), (0, "D2"), 60, False),
    "f2bb": ((1, None), (0, None), 72, False),
    "sw132": ((1, None), (2, None), 132, True),
    "b29_26": ((2, "Bb2"), (1, "F2"), 80, True),
    "r23l32": ((3, None), (0, None), 100, False),
    "k29_23": ((3, None), (1, None), 144, False),
    "r23hi": ((3, "A3"), (2, "D3"), 120, False),
    "b26_23": ((3, "D3"), (2, "Bb2"), 100, False),
    "top32_29": ((1, "C3"), (0, "A2"), 110, False),
    "k32_26": ((2, None), (0, None), 90, True),
    "top26_23": ((3, "A3"), (2, "F3"), 70, True),
}
BEAT = re.compile(
    r"(\s*Beat\(tick: \d+, hand: )(Right|Left)(, mode: \w+, dynamic: \w+, drum: )(\d)"
    r"(, location: PlayingSpot\),)"
)


def main() -> None:
    out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "ladders")
    out.mkdir(parents=True, exist_ok=True)
    source = (ROOT / "scores/dynamics-ladder.ron").read_text()
    source = source.replace('kit: "../kits/standard.ron"', 'kit: "standard"')
    for name, (right, left, bpm, swap) in VARIANTS.items():
        lines = []
        for line in source.split("\n"):
            m = BEAT.match(line)
            if m:
                hand = m.group(2)
                drum, pitch = right if hand == "Right" else left
                if swap:
                    hand = "Left" if hand == "Right" else "Right"
                pitched = f', pitch: Some("{pitch}")' if pitch else ""
                line = f"{m.group(1)}{hand}{m.group(3)}{drum}{pitched}, location: PlayingSpot),"
            lines.append(line)
        text = "\n".join(lines).replace("bpm: 100.0", f"bpm: {bpm}.0")
        (out / f"{name}.ron").write_text(text)
    print(f"{len(VARIANTS)} ladders in {out}")


if __name__ == "__main__":
    main()
