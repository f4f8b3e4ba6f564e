#!/bin/sh
# A file name is any byte string on Linux: `gpubridge render --json` with an output path that is not
# UTF-8 must render, exit 0 and print its JSON (the name with U+FFFD), not fail after the work.
#   cli_json_path.sh GPUBRIDGE SCENE OUTDIR
set -eu
out="$3/$(printf 'json-\377\376.png')"
json=$("$1" render "$2" --out "$out" --json)
rm -f "$out"
printf '%s\n' "$json" | grep -q '"pixels_written": [1-9]' || { echo "no JSON report: $json" >&2; exit 1; }
printf '%s\n' "$json" | grep -q "$(printf '"output": ".*json-\357\277\275\357\277\275.png"')" ||
  { echo "output path not reported with U+FFFD: $json" >&2; exit 1; }
echo ok
