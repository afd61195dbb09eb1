#!/usr/bin/env bash
# Play a render's hits into the shipped Pure Data patch (kits/pd/timpanist-hits.pd) headless
# and check Pd received one /timpanist/hit per contact of `render --events`, with no
# object that failed to create. Needs Pd (Debian: apt-get install puredata-core) and a
# release build (cargo build --release). Usage: tests/scripts/osc-pd.sh [SCORE.ron]
set -euo pipefail
cd "$(dirname "$0")/../.."
score=${1:-scores/tempo-change.ron}
out=$(mktemp -d)
trap 'kill "$pd" 2>/dev/null || true; rm -r "$out"' EXIT
pd -nogui -noaudio -stderr -open kits/pd/timpanist-hits.pd >"$out/pd.log" 2>&1 &
pd=$!
sleep 2
./target/release/timpanist render "$score" --wav "$out/mix.wav" --events "$out/events.json" \
    --osc 127.0.0.1:9000
sleep 1
received=$(grep -c '^hit:' "$out/pd.log" || true)
contacts=$(grep -c '"contact_s"' "$out/events.json")
if grep -Eiq "couldn't create|error" "$out/pd.log"; then
    cat "$out/pd.log" >&2
    exit 1
fi
echo "Pd received $received hits of $contacts contacts"
test "$received" -eq "$contacts"
