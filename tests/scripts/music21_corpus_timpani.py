#!/usr/bin/env python3
"""List the timpani parts in music21's own corpus, as music21 reads them: one JSON object
a line, {"path": FILE, "notes": [[offset in quarter notes, MIDI pitch], ...]}, repeats
expanded, tied continuations not new notes, a chord's pitches each a note.

    python3 tests/scripts/music21_corpus_timpani.py

Used by tests/musicxml.rs (`music21_corpus_timpani_parts`) when python3 has music21.
"""
import json
import os
import re
import zipfile

import music21

NAME = re.compile(r"<part-name[^>]*>([^<]*)</part-name>")
TIMPANI = re.compile(r"timp|pauk", re.I)


def text_of(path):
    if path.endswith(".mxl"):
        with zipfile.ZipFile(path) as z:
            return "".join(
                z.read(n).decode("utf-8", "ignore")
                for n in z.namelist()
                if n.endswith((".xml", ".musicxml")) and "META-INF" not in n
            )
    with open(path, encoding="utf-8", errors="ignore") as f:
        return f.read()


def timpani_files(root):
    for folder, _, files in sorted(os.walk(root)):
        for name in sorted(files):
            if name.endswith((".mxl", ".xml", ".musicxml")):
                path = os.path.join(folder, name)
                if any(TIMPANI.search(n) for n in NAME.findall(text_of(path))):
                    yield path


def notes(path):
    score = music21.converter.parse(path)
    part = next(p for p in score.parts if TIMPANI.search(p.partName or ""))
    try:
        part = part.expandRepeats()
    except Exception:
        pass
    out = []
    for n in part.flatten().notes:
        if n.tie is not None and n.tie.type in ("stop", "continue"):
            continue
        offset = round(float(n.getOffsetInHierarchy(part)), 6)
        out.extend([offset, p.midi] for p in n.pitches)
    return sorted(out)


def main():
    root = os.path.dirname(music21.corpus.__file__)
    for path in timpani_files(root):
        print(json.dumps({"path": path, "notes": notes(path)}), flush=True)


if __name__ == "__main__":
    main()
