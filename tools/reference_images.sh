#!/usr/bin/env bash
# The fixed set of images a change that must not change behaviour is checked against: the same
# commands with two binaries, then `compare` says which files differ (an EXR byte for byte, a PNG
# pixel for pixel).
#
#   tools/reference_images.sh render BINARY DIR    renders the set into DIR (and DIR/sha256.txt)
#   tools/reference_images.sh hash DIR             hashes DIR's images again (DIR/sha256.txt)
#   tools/reference_images.sh compare DIR_A DIR_B  lists the files that differ; exit 1 if any
#
# The set: the README's Cornell box; modern-hall 400x300 with --emission-samples 4; `relight
# --edits` on modern-hall (a light's scale, an added point light, a move, a remove, an added
# quad; every frame as EXR and PNG); the window under Xvfb with a script that adds and drags a
# light and moves an object (a screenshot after each); `recover` and `remodel` on
# ../shared/photos/cornell-box. About 10 minutes on 2 cores of lavapipe.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
shared="$repo/../shared"

# DIR/sha256.txt: a hash per image. An EXR's header holds the date it was written (capDate): it
# is hashed with that value blanked. A PNG is hashed by its size, format and pixels (its rows
# unfiltered), not its bytes: how it was deflated is the encoder's business.
hash_images() {
  (cd "$1" && find . -type f \( -name '*.png' -o -name '*.exr' \) | sort | python3 -c '
import hashlib, struct, sys, zlib

def png_pixels(data):
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    at, idat, header = 8, b"", None
    while at < len(data):
        size, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + size]
        if kind == b"IHDR": header = body
        elif kind == b"IDAT": idat += body
        at += 12 + size
    width, height, depth, colour = struct.unpack(">IIBB", header[:10])
    channels = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}[colour]
    step = max(1, channels * depth // 8)
    stride = (width * channels * depth + 7) // 8
    raw, rows, previous = zlib.decompress(idat), [], bytearray(stride)
    for y in range(height):
        kind, row = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = row[i - step] if i >= step else 0
            b, c = previous[i], previous[i - step] if i >= step else 0
            if kind == 1: row[i] = (row[i] + a) & 255
            elif kind == 2: row[i] = (row[i] + b) & 255
            elif kind == 3: row[i] = (row[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                row[i] = (row[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(row))
        previous = row
    return header[:10] + b"".join(rows)

for name in sys.stdin.read().split():
    data = bytearray(open(name, "rb").read())
    if name.endswith(".png"):
        data = png_pixels(bytes(data))
    key = b"capDate\0string\0"
    at = data.find(key)
    if name.endswith(".exr") and at >= 0:
        start = at + len(key)
        size = struct.unpack("<i", data[start:start + 4])[0]
        data[start + 4:start + 4 + size] = bytes(size)
    print(hashlib.sha256(data).hexdigest() + "  " + name)' >sha256.txt)
}

render() {
  local obscura dir
  obscura="$(realpath "$1")"
  dir="$(realpath -m "$2")"
  mkdir -p "$dir"
  local work
  work=$(mktemp -d)
  trap 'rm -rf "$work"' RETURN
  cd "$repo"
  local log="$dir/log.txt"
  : >"$log"
  run() { echo "+ $*" >>"$log"; "$@" >>"$log" 2>&1; }

  run "$obscura" render scenes/cornell-box/cornell-box.gltf -o "$dir/cornell-box.png"
  run "$obscura" render "$shared/scenes/modern-hall/modern-hall.gltf" --width 400 --height 300 \
    --emission-samples 4 -o "$dir/modern-hall.exr"

  cat >"$work/edits.json" <<'JSON'
[{"light": "light_rectangle_6", "scale": 0.3},
 {"add_light": {"type": "point", "name": "bulb", "position": [0.0, 3.0, 1.0], "color": [1, 0.8, 0.6], "intensity": 5}},
 {"move": "Mesh017", "translate": [0.1, 0.0, 0.1]},
 {"remove_light": "bulb"},
 {"add_light": {"type": "quad", "name": "panel", "corner": [0.0, 3.0, 1.0], "edge1": [0.5, 0, 0], "edge2": [0, 0, 0.5],
                "emission": [4, 4, 4]}},
 {"light": "panel", "color": [0.5, 0.7, 1.0]},
 {"remove": "Mesh017"}]
JSON
  run "$obscura" relight "$shared/scenes/modern-hall/modern-hall.gltf" --edits "$work/edits.json" \
    -o "$dir/relight" --width 200 --height 150 --spp 2 --png
  rm -f "$dir/relight/edits.jsonl" # timings

  cat >"$work/script.json" <<'JSON'
[{"frame": 3, "panel": {"add_light": {"type": "point", "name": "bulb", "position": [0.0, 1.5, 0.3], "color": [1, 1, 1], "intensity": 2}}},
 {"frame": 6, "panel": {"move_light": "bulb", "position": [0.2, 1.5, 0.3]}},
 {"frame": 7, "panel": {"move_light": "bulb", "position": [0.4, 1.5, 0.3]}},
 {"frame": 9, "screenshot": "SHOTS/after-drag.png"},
 {"frame": 10, "panel": {"light": "light_rectangle_1", "scale": 0.5}},
 {"frame": 11, "panel": {"move": "cube_2", "translate": [0.1, 0.0, 0.05]}},
 {"frame": 12, "panel": {"move": "cube_2", "translate": [0.1, 0.0, 0.05]}},
 {"frame": 14, "screenshot": "SHOTS/after-move.png"},
 {"frame": 15, "panel": {"remove_light": "bulb"}},
 {"frame": 17, "screenshot": "SHOTS/after-remove.png"}]
JSON
  mkdir -p "$dir/view/window" "$dir/view/offscreen"
  sed "s|SHOTS|$dir/view/window|g" "$work/script.json" >"$work/window.json"
  sed "s|SHOTS|$dir/view/offscreen|g" "$work/script.json" >"$work/offscreen.json"
  run xvfb-run -a -s "-screen 0 1024x768x24" "$obscura" view scenes/cornell-box/cornell-box.gltf \
    --width 160 --height 160 --frames 20 --script "$work/window.json" --no-denoise --no-panel \
    --screenshot "$dir/view/window/last.png"
  run "$obscura" view scenes/cornell-box/cornell-box.gltf --offscreen --width 160 --height 160 --frames 20 \
    --script "$work/offscreen.json" --no-denoise --no-panel --screenshot "$dir/view/offscreen/last.png"

  run "$obscura" recover scenes/cornell-box/cornell-box.gltf --photos "$shared/photos/cornell-box/lights.json" \
    -o "$dir/recover"
  cat >"$work/remodel.json" <<'JSON'
[{"light": "shot0", "scale": 0}, {"remove_light": "shot1"},
 {"add_light": {"type": "point", "name": "lamp", "position": [0.45, 1.55, -0.1], "color": [1, 1, 1], "intensity": 2.387}},
 {"light": "lamp", "color": [1, 0.9, 0.8]},
 {"remove": "cube_1"}]
JSON
  run "$obscura" remodel "$dir/recover" --edits "$work/remodel.json" -o "$dir/remodel.exr"
  rm -f "$dir/recover/recover.json" # timings; its figures are in the images
  hash_images "$dir"
  echo "$(wc -l <"$dir/sha256.txt") images in $dir"
}

compare() {
  local differ=0
  while read -r sum file; do
    other=$(grep -F "  $file" "$2/sha256.txt" | cut -d' ' -f1 || true)
    if [[ "$other" != "$sum" ]]; then
      echo "differs: $file"
      differ=1
    fi
  done <"$1/sha256.txt"
  [[ $(wc -l <"$1/sha256.txt") == $(wc -l <"$2/sha256.txt") ]] || { echo "the sets hold different files"; differ=1; }
  ((differ)) || echo "all $(wc -l <"$1/sha256.txt") images identical (EXR bytes, PNG pixels)"
  return $differ
}

case "${1:-}" in
  render) render "$2" "$3" ;;
  hash) hash_images "$2" ;;
  compare) compare "$2" "$3" ;;
  *) echo "usage: $0 render BINARY DIR | compare DIR_A DIR_B" >&2; exit 2 ;;
esac
