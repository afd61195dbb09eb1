#!/usr/bin/env bash
# Autosave against a real crash: open a copy of the etude in the real editor (under Xvfb),
# delete every beat (Ctrl+A, Delete), wait for the autosave, kill -9 the editor, start it
# again, take the offer (Tab, Return: the dialog's Restore), save (Ctrl+S) and check the
# saved file has no beats and the autosave is gone. Needs Xvfb and xdotool
# (apt-get install -y xvfb xdotool) and a release build: cargo build --release.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
bin="$root/target/release/timpanist"
work=$(mktemp -d)
export XDG_CONFIG_HOME="$work/cfg" DISPLAY=:97
sed "s|\"../kits/standard.ron\"|\"$root/kits/standard.ron\"|" "$root/scores/etude-modes.ron" >"$work/etude.ron"
Xvfb :97 -screen 0 1600x1000x24 >/dev/null 2>&1 &
xvfb=$!
trap 'kill $xvfb 2>/dev/null; rm -rf "$work"' EXIT
sleep 1
window() { # wait for the editor's window, print its id
    for _ in $(seq 60); do
        if id=$(xdotool search --name 'etude|timpanist' 2>/dev/null | head -1) && [ -n "$id" ]; then
            sleep 2; echo "$id"; return; fi
        sleep 0.5
    done
    echo "no editor window" >&2; exit 1
}
"$bin" edit "$work/etude.ron" 2>"$work/first.log" &
editor=$!
w=$(window)
xdotool windowfocus "$w"; xdotool mousemove 700 500
xdotool key --window "$w" ctrl+a; sleep 0.5; xdotool key --window "$w" Delete
for _ in $(seq 20); do [ -f "$work/cfg/timpanist/recovery.ron" ] && break; sleep 0.5; done
test -f "$work/cfg/timpanist/recovery.ron" || { echo "no autosave after the edit" >&2; exit 1; }
kill -9 "$editor"; wait "$editor" 2>/dev/null || true
echo "killed the editor with the edit unsaved; the autosave holds $(grep -c 'Beat(' "$work/cfg/timpanist/recovery.ron" || true) beats"
"$bin" edit "$work/etude.ron" 2>"$work/second.log" &
editor=$!
w=$(window)
grep -q "offered back" "$work/second.log" || { echo "the restart did not offer the autosave" >&2; exit 1; }
xdotool windowfocus "$w"; xdotool mousemove 700 500
xdotool key --window "$w" Tab; sleep 0.3; xdotool key --window "$w" Return; sleep 1
xdotool key --window "$w" ctrl+s
for _ in $(seq 20); do [ -f "$work/cfg/timpanist/recovery.ron" ] || break; sleep 0.5; done
kill "$editor" 2>/dev/null || true
beats=$(grep -c 'Beat(' "$work/etude.ron" || true)
if [ "$beats" != 0 ] || [ -f "$work/cfg/timpanist/recovery.ron" ]; then
    echo "restore failed: $beats beats saved, autosave left: $(ls "$work/cfg/timpanist")" >&2; exit 1
fi
echo "restarted: the edit was offered back, restored and saved (0 beats); the autosave is gone"
