#!/usr/bin/env bash
# Open a lesson pack's index.html in headless Chromium and check what a reader would see:
# every plot shown (each <img> decoded with a width), no image or audio file missing (the
# page's own check: `data-missing` on <body>), and nothing in the page's console (the page
# logs nothing; a script error or a failed load would show as a CONSOLE line). Then the same page copied alone into an empty folder
# must report its files missing (the check can fail). Writes a screenshot of the page.
# Not in CI. Needs Chromium (Debian: apt-get install chromium) and a release build
# (cargo build --release).
# Usage: tests/scripts/pack-chromium.sh [SCORE.ron] [SCREENSHOT.png]
set -euo pipefail
cd "$(dirname "$0")/../.."
score=${1:-scores/etude-modes.ron}
shot=${2:-}
browser=$(command -v chromium || command -v chromium-browser || command -v google-chrome || true)
if [ -z "$browser" ]; then
    echo "no Chromium installed (apt-get install chromium): skipped" >&2
    exit 2
fi
out=$(mktemp -d)
trap 'rm -r "$out"' EXIT
./target/release/timpanist export-pack "$score" -o "$out/pack"

# Load the page with its files; dump the DOM once the page's script has run.
open_page() { # PAGE DOM LOG
    timeout 120 "$browser" --headless --no-sandbox --disable-gpu --user-data-dir="$out/profile" \
        --disable-background-networking --disable-component-update --disable-sync \
        --virtual-time-budget=10000 --enable-logging=stderr --v=0 \
        --dump-dom "file://$1" >"$2" 2>"$3"
}
open_page "$out/pack/index.html" "$out/dom.html" "$out/log.txt"
plots=$(grep -c '<img ' "$out/pack/index.html")
body=$(grep -o '<body[^>]*>' "$out/dom.html")
echo "page: $body ($plots plots in the page)"
status=0
if [[ "$body" != *"data-plots-shown=\"$plots\""* ]]; then
    echo "FAIL: not every plot was shown" >&2
    status=1
fi
if [[ "$body" == *data-missing* ]]; then
    echo "FAIL: files missing" >&2
    status=1
fi
if grep -E ':CONSOLE|Failed to load resource' "$out/log.txt"; then
    echo "FAIL: the console reports errors" >&2
    status=1
fi

# The control: index.html without its folders must say what is missing.
mkdir "$out/alone"
cp "$out/pack/index.html" "$out/alone/"
open_page "$out/alone/index.html" "$out/alone-dom.html" "$out/alone-log.txt"
alone=$(grep -o '<body[^>]*>' "$out/alone-dom.html")
if [[ "$alone" != *data-missing=*plots/tip-heights.svg*audio/performance.wav* ]]; then
    echo "FAIL: the page alone did not report its missing files: $alone" >&2
    status=1
else
    echo "control: the page alone reports its files missing"
fi

if [ -n "$shot" ]; then
    timeout 120 "$browser" --headless --no-sandbox --disable-gpu --user-data-dir="$out/profile" \
        --hide-scrollbars --virtual-time-budget=10000 --window-size=1300,2600 \
        --screenshot="$(realpath -m "$shot")" "file://$out/pack/index.html" 2>/dev/null
    echo "screenshot: $shot"
fi
if [ "$status" -eq 0 ]; then
    echo "ok: the pack's page shows its $plots plots with no missing resource"
fi
exit "$status"
