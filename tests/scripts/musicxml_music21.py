#!/usr/bin/env python3
"""Read a MusicXML file timpanist exported with music21 (an independent reader) and
compare every note with the JSON the test wrote: a list of [offset in quarter notes from
the start, MIDI pitch, articulation class name or ""], one per beat.

    python3 tests/scripts/musicxml_music21.py OUT.musicxml EXPECTED.json

Prints the notes it read and "agree: N notes" (exit 0), or each difference (exit 1).
Used by tests/musicxml_export.rs when python3 has music21 (pip install music21).
"""
import json
import sys

import music21


def read(path):
    """(offset in quarters, MIDI pitch, articulation) of every sounding note; tied
    continuations are not new notes."""
    score = music21.converter.parse(path, forceSource=True)
    part = score.parts[0]
    notes = []
    for n in part.flatten().notes:
        if n.tie is not None and n.tie.type in ("stop", "continue"):
            continue
        offset = float(n.getOffsetInHierarchy(part))
        arts = [a.__class__.__name__ for a in n.articulations]
        art = next((a for a in arts if a in ("Accent", "StrongAccent", "Staccato", "Tenuto")), "")
        for p in n.pitches:
            notes.append((round(offset, 6), p.midi, art))
    return sorted(notes)


def main():
    path, expected_path = sys.argv[1], sys.argv[2]
    got = read(path)
    with open(expected_path) as f:
        want = sorted((round(o, 6), p, a) for o, p, a in json.load(f))
    for o, p, a in got:
        print(f"  {o:g} {p} {a}".rstrip())
    bad = [(w, g) for w, g in zip(want, got) if w != g]
    if len(got) != len(want) or bad:
        print(f"differ: {len(got)} notes read, {len(want)} expected; first differences (want, got): {bad[:5]}")
        return 1
    print(f"agree: {len(got)} notes (offset, pitch, articulation)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
