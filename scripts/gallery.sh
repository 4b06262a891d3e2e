#!/usr/bin/env bash
# Remakes the stills of docs/gallery.md: runs each scene of scenes/ for the frames its still needs,
# renders the chosen frame with POV-Ray at 480 x 360 (`soak render`, docs/rendering.md), reduces it to
# 256 colours with ffmpeg (palettegen / paletteuse) and writes docs/gallery/NAME.png. Side-by-side
# stills are two such renders joined with ffmpeg's hstack, each half labelled.
#
#   scripts/gallery.sh [--work DIR] [--fresh] [STILL...]
#
# STILL: any of the names below (default: all), e.g. `scripts/gallery.sh fig4 fig5 fig9`.
#   fig1 fig3a fig3b fig4 fig5 fig6a fig6b fig9 dam_break drape_sphere chen_fig8 chen_fig9 garments obj_body sweep
# --work DIR: where the runs and renders go (default /tmp/soak-gallery). A run already there with the
#   frames a still needs is reused (its run.json must say status ok and at least those frames, and be
#   newer than the scene file and every pattern file); pass --fresh to run every scene again.
# Environment: SOAK (default build/soak), THREADS (default 2); OMP_WAIT_POLICY defaults to PASSIVE.
#
# At the end it prints the numbers the captions quote, measured on the runs (scripts/gallery_numbers.py).
# Needs povray and ffmpeg (scripts/setup.sh installs them). Times on 2 shared cores are in
# docs/gallery.md. The runs are shortened to the still's frame (`soak run --frames F`), which gives
# the same frames as a whole run.
set -euo pipefail
cd "$(dirname "$0")/.."
repo="$PWD"
soak="${SOAK:-$repo/build/soak}"
threads="${THREADS:-2}"
work=/tmp/soak-gallery
fresh=0
stills=()
all=(fig1 fig3a fig3b fig4 fig5 fig6a fig6b fig9 dam_break drape_sphere chen_fig8 chen_fig9 garments obj_body sweep)
while [ $# -gt 0 ]; do
  case "$1" in
    --work) work="$2"; shift 2 ;;
    --fresh) fresh=1; shift ;;
    -h|--help) sed -n '2,18p' "$0"; exit 0 ;;
    -*) echo "gallery.sh: unknown option $1" >&2; exit 1 ;;
    *) stills+=("$1"); shift ;;
  esac
done
[ ${#stills[@]} -gt 0 ] || stills=("${all[@]}")
for s in "${stills[@]}"; do
  [[ " ${all[*]} " == *" $s "* ]] || { echo "gallery.sh: no still named $s (${all[*]})" >&2; exit 1; }
done
[ -x "$soak" ] || { echo "gallery.sh: $soak not found: build soak first (scripts/setup.sh)" >&2; exit 1; }
for p in povray ffmpeg; do
  command -v "$p" >/dev/null || { echo "gallery.sh: $p not found (scripts/setup.sh installs it)" >&2; exit 1; }
done
mkdir -p "$work" docs/gallery
# Sleeping OpenMP threads: on a shared machine a spinning partner thread costs a time slice at each
# barrier (docs/performance.md); the results do not depend on it.
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-PASSIVE}"

font=/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf
log() { printf '%s gallery: %s\n' "$(date +%T)" "$*" >&2; }

# run SCENE FRAMES: simulates scenes/SCENE.json up to frame FRAMES into $work/SCENE (reused when done
# and newer than the scene file and every pattern file, which a scene may sew)
run() {
  local scene="$1" frames="$2" dir="$work/$1"
  if [ "$fresh" = 0 ] && [ -f "$dir/run.json" ] &&
    [ -z "$(find "scenes/$scene.json" patterns -newer "$dir/run.json" -print -quit)" ] &&
    python3 - "$dir/run.json" "$frames" <<'EOF'
import json, sys
r = json.load(open(sys.argv[1]))
sys.exit(0 if r.get("status") == "ok" and r.get("frames", -1) >= int(sys.argv[2]) else 1)
EOF
  then
    log "$scene: reusing the run in $dir"
    return
  fi
  local t0=$SECONDS
  log "$scene: running $frames frames"
  "$soak" run "scenes/$scene.json" -o "$dir" --frames "$frames" --threads "$threads" --overwrite --quiet
  log "$scene: ran $frames frames in $((SECONDS - t0)) s"
}

# render SCENE FRAME OUT.png [soak render options...]: one 480 x 360 frame, full colour
render() {
  local scene="$1" frame="$2" out="$3"
  shift 3
  local t0=$SECONDS rdir="$work/render/$scene"
  "$soak" render "$work/$scene" -o "$rdir" --frames "$frame" --width 480 --height 360 --no-video \
    --jobs 1 --quiet "$@"
  cp "$rdir/$(printf 'frame_%04d.png' "$frame")" "$out"
  log "$scene: rendered frame $frame in $((SECONDS - t0)) s"
}

# palette IN.png NAME: 256 colours into docs/gallery/NAME.png
palette() {
  ffmpeg -nostdin -v error -y -i "$1" -vf "split[a][b];[a]palettegen[p];[b][p]paletteuse" \
    "docs/gallery/$2.png"
  log "wrote docs/gallery/$2.png"
}

# label IN.png TEXT OUT.png: TEXT in the top left corner
label() {
  ffmpeg -nostdin -v error -y -i "$1" -vf "drawtext=fontfile=$font:text='$2':x=8:y=8:fontsize=18:\
fontcolor=black:box=1:boxcolor=white@0.7:boxborderw=4" "$3"
}

# pair LEFT.png LEFT_LABEL RIGHT.png RIGHT_LABEL NAME: side by side, 960 x 360, into docs/gallery/NAME.png
pair() {
  local tmp="$work/render/pair"
  mkdir -p "$tmp"
  label "$1" "$2" "$tmp/left.png"
  label "$3" "$4" "$tmp/right.png"
  ffmpeg -nostdin -v error -y -i "$tmp/left.png" -i "$tmp/right.png" -filter_complex hstack "$tmp/both.png"
  palette "$tmp/both.png" "$5"
}

# one still: SCENE FRAME [render options...] -> docs/gallery/SCENE.png
still() {
  local scene="$1" frame="$2"
  shift 2
  run "$scene" "$frame"
  render "$scene" "$frame" "$work/render/$scene.png" "$@"
  palette "$work/render/$scene.png" "$scene"
}

mkdir -p "$work/render"

# side_by_side LEFT RIGHT FRAME LEFT_LABEL RIGHT_LABEL NAME [render options...]: both scenes at FRAME
# into docs/gallery/NAME.png, and each half alone as docs/gallery/SCENE.png (README.md shows 9(a))
side_by_side() {
  local left="$1" right="$2" frame="$3" leftLabel="$4" rightLabel="$5" name="$6"
  shift 6
  for scene in "$left" "$right"; do
    run "$scene" "$frame"
    render "$scene" "$frame" "$work/render/$scene.png" "$@"
    palette "$work/render/$scene.png" "$scene"
  done
  pair "$work/render/$left.png" "$leftLabel" "$work/render/$right.png" "$rightLabel" "$name"
}

still_fig1() { still fig1_jet 100 --camera 2.3,1.9,3.3 --look-at 0,1.05,0; }
still_fig3a() { still fig3a_cube_on_cloth 100 --camera 1.9,2.0,2.4 --look-at 0,0.75,0; }
still_fig3b() { still fig3b_cube_on_cloth_wet 40 --camera 1.9,2.5,2.6 --look-at 0,0.7,0; }
# Fig. 4 at 0.18 s, while its layers differ; run on to 0.42 s, where the caption says both are nearly black
still_fig4() {
  run fig4_absorption 28
  render fig4_absorption 12 "$work/render/fig4_absorption.png" --camera 0.3,0.32,0.75 --look-at 0,0.14,0
  palette "$work/render/fig4_absorption.png" fig4_absorption
}
still_fig5() {
  side_by_side fig5b_dip_no_gravity fig5c_dip_gravity 100 "5(b) no gravity term, t = 3 s" \
    "5(c) gravity term, t = 3 s" fig5_dip --camera 1.0,1.4,3.0 --look-at 0,0.72,0
}
still_fig6a() { still fig6a_drip_uniform 60 --look-at 0,1.4,0 --zoom 1.3; }
still_fig6b() { still fig6b_drip_diagonal 60 --look-at 0,1.2,0 --zoom 1.3; }
still_fig9() {
  side_by_side fig9a_ball_no_sticking fig9b_ball_sticking 233 "9(a) no sticking, t = 7 s" \
    "9(b) sticking, t = 7 s" fig9_ball --camera 1.6,1.6,2.0 --look-at 0,0.7,0
}
still_dam_break() { still dam_break 20; }
still_drape_sphere() { still drape_sphere 60; }
still_chen_fig8() {
  still chen_fig8_silk_sphere_dry 240 --particles
  still chen_fig8_silk_sphere_wet 240 --particles
}
still_chen_fig9() {
  still chen_fig9_garment_rain_dry 300 --particles
  still chen_fig9_garment_rain_wet 300 --particles
}
still_garments() {
  still garment_dress_rain 300 --particles
  still garment_skirt 90
}
# the moving-body shirt at 3 s (arms raised) on the mannequin and on its OBJ sequence (soak export-body)
still_obj_body() {
  "$soak" export-body scenes/garment_tshirt_moving.json -o scenes/obj_body/frames --overwrite --quiet
  mkdir -p "$work/obj_body" "$work/render/obj_body"
  local scene
  for scene in garment_tshirt_moving obj_body/garment_tshirt_obj_body; do
    run "$scene" 90
    render "$scene" 90 "$work/render/$scene.png" --particles --camera 0.9,1.6,2.0 --look-at 0,1.2,0
  done
  pair "$work/render/garment_tshirt_moving.png" "mannequin, t = 3 s" \
    "$work/render/obj_body/garment_tshirt_obj_body.png" "its OBJ sequence, t = 3 s" garment_obj_body
}
# the contact sheet of sweeps/fig5c_wicking.json (docs/sweeps.md; its complete variants are reused)
still_sweep() {
  local dir="$work/sweep_fig5c_wicking"
  [ "$fresh" = 1 ] && rm -rf "$dir"
  # exit 1 when a variant is not complete: the sheet is still drawn, and says which
  "$soak" sweep sweeps/fig5c_wicking.json -o "$dir" --jobs 2 --threads "$threads" -q || log "sweep: not every variant complete"
  palette "$dir/contact_sheet.png" sweep_fig5c_wicking
}

for s in "${stills[@]}"; do
  t0=$SECONDS
  "still_$s"
  log "$s: done in $((SECONDS - t0)) s"
done

# the numbers the captions of docs/gallery.md quote, measured on these runs (the demos quote none;
# obj_body's are scripts/obj-body.sh's)
measured=()
for s in "${stills[@]}"; do
  case "$s" in dam_break | drape_sphere | obj_body) ;; *) measured+=("$s") ;; esac
done
if [ ${#measured[@]} -gt 0 ]; then
  log "the numbers the captions quote (scripts/gallery_numbers.py):"
  /usr/bin/python3 scripts/gallery_numbers.py "$work" "${measured[@]}"
fi
