#!/usr/bin/env bash
# Renders a report.html to PNG in headless Chromium, to look at it as a reader would.
#   scripts/render-report.sh frictionid-out/fmm-fit/fit/report.html fit.png [width]
# Needs Debian's chromium (apt-get install chromium). The page loads nothing from outside,
# so no network is needed; the flags keep Chromium from trying.
set -euo pipefail
html="$(realpath "$1")"
png="$(realpath -m "$2")"
width="${3:-1280}"
profile="$(mktemp -d)"
trap 'rm -rf "$profile"' EXIT
# Tall window: the whole page in one image (Chromium clips to the window).
chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
  --disable-background-networking --disable-component-update --disable-sync \
  --hide-scrollbars --user-data-dir="$profile" \
  --window-size="${width},${HEIGHT:-6000}" --screenshot="$png" "file://$html" 2>/dev/null
echo "wrote $png"
