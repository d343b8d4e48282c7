#!/usr/bin/env bash
# Remakes dashboard-all-presets.png (docs/ci/README.md, "Three commits, every preset"): a scratch clone of this
# checkout, installed in a venv of its own, cross-checks every preset against its baseline on three commits
# (as it is; demo-3p's meshes 30 % stiffer; a notes file), recorded in one history store; the dashboard's front
# page drawn in headless Chromium.  Prints each commit's exit status (0: all PASS; 1: a FAIL).
# Usage: bash docs/ci/dashboard-all-presets.sh   (about 5 minutes on two cores; needs chromium)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
git clone -q "$(cd "$here/../.." && pwd)" "$work/gearcheck"
python3 -m venv "$work/venv"
"$work/venv/bin/pip" install -q -e "$work/gearcheck" >/dev/null
cd "$work/gearcheck"
git config user.name "gearcheck docs" && git config user.email "docs@gearcheck.invalid"
record() {
    local status=0
    "$work/venv/bin/gearcheck" crosscheck --all --baseline --history "$work/history.sqlite" --out "$work/out" \
        >/dev/null || status=$?
    echo "$(git log -1 --format='%h %s'): exit $status"
}
record
sed -i 's/mean = 8.0e8/mean = 1.04e9/' src/gearcheck/train/presets/demo-3p.toml
git commit -qam "demo-3p: meshes 30 % stiffer (8.0e8 to 1.04e9 N/m)"
record
echo "Notes, no physics." > NOTES.md && git add NOTES.md && git commit -qm "A notes file"
record
"$work/venv/bin/gearcheck" dashboard "$work/history.sqlite" -o "$work/site" >/dev/null
chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --window-size=1200,1400 \
    --screenshot="$here/dashboard-all-presets.png" "file://$work/site/index.html" 2>/dev/null
echo "wrote $here/dashboard-all-presets.png"
