#!/usr/bin/env bash
# Lays the real VLP-16 + fisheye set (../shared/datasets/acfr-vlp16-chessboard) out as a user's
# folder of recordings (clouds/, images/, camera.yaml, target.json; symlinks, no copies), the
# input of the real-data figures in docs/results.md:
#
#   scripts/acfr_folder.sh /tmp/acfr_folder
#   /usr/bin/time -v build/calibench calibrate --dataset /tmp/acfr_folder --out /tmp/acfr.json
set -euo pipefail
out=${1:?usage: scripts/acfr_folder.sh OUT_DIR}
acfr=$(cd "$(dirname "$0")/.." && cd "${CALIBENCH_SHARED_DIR:-../shared}/datasets/acfr-vlp16-chessboard" && pwd)
rm -rf "$out"
mkdir -p "$out/clouds" "$out/images"
for n in $(seq 40); do
  ln -s "$acfr/pcd/pose${n}_full.pcd" "$out/clouds/pose$n.pcd"
  ln -s "$acfr/images/pose$n.png" "$out/images/pose$n.png"
done
ln -s "$acfr/camera_info.yaml" "$out/camera.yaml"
cat > "$out/target.json" <<'JSON'
{"type": "checkerboard", "inner_corners": [5, 7], "square_size": 0.095, "board_size": [0.61, 0.85]}
JSON
echo "wrote $out (40 pairs)"
