#!/usr/bin/env bash
# A side-by-side movie of a dry and a wet run of the same scene (Chen 2012 Fig. 8 and Fig. 9 compare
# them): runs both scenes, renders every frame with POV-Ray (`soak render`, the scene's camera) and
# joins the two movies with ffmpeg's hstack, each half labelled.
#
#   scripts/dry-wet-movie.sh [--work DIR] [--frames N] [--width W] [--height H] DRY.json WET.json OUT.mp4
#                            [-- RENDER_OPTION...]
#
# e.g. (docs/gallery/chen_fig9_dry_wet.mp4) scripts/dry-wet-movie.sh scenes/chen_fig9_garment_rain_dry.json \
#        scenes/chen_fig9_garment_rain_wet.json docs/gallery/chen_fig9_dry_wet.mp4 \
#        -- --particles --camera 0.9,1.5,2.0 --look-at 0,1.2,0
# --work DIR: where the runs and renders go (default /tmp/soak-dry-wet); --frames N: only the first N
# frames (default: the scenes' own); --width / --height: of each half (default 480 x 360); after --:
# options for both renders (`soak render`, docs/cli.md), e.g. one camera for both halves.
# Environment: SOAK (default build/soak), THREADS (default 2).
# Needs povray and ffmpeg (scripts/setup.sh installs them). The Fig. 9 pair (300 frames each) takes
# about 15 minutes on 2 cores, most of it POV-Ray.
set -euo pipefail
cd "$(dirname "$0")/.."
soak="${SOAK:-$PWD/build/soak}"
threads="${THREADS:-2}"
work=/tmp/soak-dry-wet
width=480
height=360
frames=()
args=()
render=()
while [ $# -gt 0 ]; do
  case "$1" in
    --work) work="$2"; shift 2 ;;
    --frames) frames=(--frames "$2"); shift 2 ;;
    --width) width="$2"; shift 2 ;;
    --height) height="$2"; shift 2 ;;
    --) shift; render=("$@"); break ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
    -*) echo "dry-wet-movie.sh: unknown option $1" >&2; exit 1 ;;
    *) args+=("$1"); shift ;;
  esac
done
if [ ${#args[@]} -ne 3 ]; then
  echo "dry-wet-movie.sh: expected DRY.json WET.json OUT.mp4 (--help)" >&2
  exit 1
fi
dry="${args[0]}" wet="${args[1]}" out="${args[2]}"
for f in "$dry" "$wet"; do [ -f "$f" ] || { echo "dry-wet-movie.sh: no scene file $f" >&2; exit 1; }; done
for tool in povray ffmpeg; do
  command -v "$tool" > /dev/null || { echo "dry-wet-movie.sh: needs $tool (scripts/setup.sh)" >&2; exit 1; }
done
font=/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf
mkdir -p "$work"
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-PASSIVE}"

# movie SCENE.json NAME: run and render into $work/NAME, the movie at $work/NAME/render/movie.mp4
movie() {
  echo "dry-wet-movie: $2: running $1" >&2
  "$soak" run "$1" -o "$work/$2" --threads "$threads" --overwrite --quiet "${frames[@]}"
  echo "dry-wet-movie: $2: rendering" >&2
  "$soak" render "$work/$2" -o "$work/$2/render" --width "$width" --height "$height" --quiet "${render[@]}"
}
movie "$dry" dry
movie "$wet" wet
text="fontfile=$font:fontsize=18:fontcolor=black:box=1:boxcolor=white@0.7:boxborderw=4:x=8:y=8"
ffmpeg -nostdin -v error -y -i "$work/dry/render/movie.mp4" -i "$work/wet/render/movie.mp4" -filter_complex \
  "[0:v]drawtext=text='dry':$text[a];[1:v]drawtext=text='wet':$text[b];[a][b]hstack=shortest=1" \
  -pix_fmt yuv420p "$out"
echo "dry-wet-movie: wrote $out" >&2
