#!/usr/bin/env bash
# Build the Debian package, install it, and use it as a new user would: from `/`, with an
# empty home, render an installed demo score and list the demos; then remove it. Needs
# root (apt) and cargo-deb (`cargo install cargo-deb`). Not part of .ci/run (it adds a
# release build and the cargo-deb install, several minutes); run by hand before a release.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo deb --strip
deb=$(ls -t target/debian/timpanist_*.deb | head -1)
apt-get install -y -qq "./$deb"
home=$(mktemp -d)
trap 'rm -rf "$home"; apt-get remove -y -qq timpanist' EXIT
cd /
HOME=$home timpanist demos
HOME=$home timpanist render /usr/share/timpanist/scores/etude-modes.ron \
    --wav "$home/etude.wav" --stats | tee "$home/out.txt"
grep -q "database: /usr/share/timpanist/mocap" "$home/out.txt"
test -s "$home/etude.wav"
test -f /usr/share/applications/timpanist.desktop
test -f /usr/share/icons/hicolor/256x256/apps/timpanist.png
echo "deb-check: ok ($deb)"
