#!/usr/bin/env bash
# Makes the before/after pictures of docs/curving.md, docs/interpolation.md and docs/mechanics.md
# with the built example programs:
#
#   docs/make_pictures.sh [BUILD_DIR]        # default ./build
#
# docs/images/ gets only pictures of meshes the programs make themselves: curve_mesh's demo
# (a boundary-layer O-mesh around a cylinder of radius 0.5, 128 x 64 quads, first cell 1e-5,
# aspect ratio ≥ 1000) curved into P2 by snapping alone (--method none), by the RBF regularizer
# and by blending (the default); each seen whole around the body and zoomed on one wall cell.
#
# With MESHMOTION_DATA pointing at a folder holding su2_30p30n_rans_L1_coarse.su2, it also
# draws the 30P30N slat cove, into BUILD_DIR/pictures/ only: that mesh's licence is not the
# project's, so neither the mesh nor pictures of it go into the repository.
set -euo pipefail

build=${1:-./build}
docs=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
curve_mesh=$build/examples/curve_mesh
if [[ ! -x $curve_mesh ]]; then
  echo "make_pictures.sh: $curve_mesh not found (build the curve_mesh target first, or pass the build dir)" >&2
  exit 1
fi
images=$docs/images
mkdir -p "$images"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

# Whole body, and the middle of one wall cell: the cell between the wall nodes at 0° and 2.8°
# (y = 0 .. 0.0245), whose wall edge snapping bends outwards by 1.5e-4 (15 first-cell heights)
# at y = 0.0123; 1e-3 of its length is shown, at 7 pixels per first-cell height.
body=-0.75,0.75,-0.75,0.75
wall=0.4994,0.5008,0.0118,0.0128

for method in none rbf blend; do
  for view in body wall; do
    zoom=$body
    [[ $view == wall ]] && zoom=$wall
    svg=$images/cylinder_${method}_${view}.svg
    # curve_mesh exits with 2 when it leaves invalid cells, as snapping alone does here.
    { "$curve_mesh" --demo --method "$method" -o "$scratch/cylinder_$method.msh" --svg "$svg" --zoom "$zoom" 2>/dev/null ||
      [[ $? == 2 ]]; } | grep -E "certified scaled Jacobian|^wrote" | sed "s|^|$method/$view: |"
  done
done

# The same demo curved at order 3 (cubic edges, drawn as polylines on their Lagrange curve):
# the wall cell, and the first layers over 0.1 of the wall.
near=0.495,0.56,-0.03,0.03
for method in none blend; do
  for view in wall near; do
    zoom=$wall
    [[ $view == near ]] && zoom=$near
    svg=$images/cylinder_p3_${method}_${view}.svg
    { "$curve_mesh" --demo --order 3 --method "$method" -o "$scratch/cylinder_p3_$method.msh" --svg "$svg" --zoom "$zoom" \
      2>/dev/null || [[ $? == 2 ]]; } | grep -E "certified scaled Jacobian|^wrote" | sed "s|^|P3 $method/$view: |"
  done
done

# Mesh motion (docs/interpolation.md, docs/mechanics.md): the curved demo's wall rotated 90°
# about its centre, the farfield fixed, by RBF, lineal springs and stiffened elasticity; Knupp
# skew, invalid cells ringed.
move_mesh=$build/examples/move_mesh
mesh_quality=$build/examples/mesh_quality
if [[ -x $move_mesh && -x $mesh_quality ]]; then
  "$curve_mesh" --demo -o "$scratch/cylinder.msh" >/dev/null 2>&1
  for method in rbf spring sle; do
    # move_mesh exits with 2 when it leaves invalid cells, as springs and elasticity do here.
    { "$move_mesh" "$scratch/cylinder.msh" -o "$scratch/rotated_$method.msh" --group wall --rotate 90 --center 0,0 \
      --fixed farfield --method "$method" 2>/dev/null || [[ $? == 2 ]]; } | grep -E "skew after" | sed "s|^|rotate 90 $method: |"
    "$mesh_quality" "$scratch/rotated_$method.msh" --metric skew --svg "$images/rotate90_$method.svg" --zoom "$body" >/dev/null
  done
else
  echo "make_pictures.sh: move_mesh or mesh_quality not built, motion pictures skipped" >&2
fi

data=${MESHMOTION_DATA:-}
if [[ -n $data && -f $data/su2_30p30n_rans_L1_coarse.su2 ]]; then
  out=$build/pictures
  mkdir -p "$out"
  # The slat cove (metres), and the flap's leading edge under the main element's trailing
  # edge, where snapping alone leaves its worst cells.
  for view in slat_cove:-0.042,0.012,-0.036,0.006 flap:0.395,0.465,-0.022,0.016; do
    for method in none rbf; do
      "$curve_mesh" "$data/su2_30p30n_rans_L1_coarse.su2" -o "$scratch/30p30n_$method.msh" --method "$method" \
        --group farfield --geometry straight --svg "$out/30p30n_${view%%:*}_$method.svg" --zoom "${view#*:}" 2>/dev/null |
        grep -E "certified scaled Jacobian|^wrote" | sed "s|^|30p30n ${view%%:*} $method: |"
    done
  done
fi
ls -l "$images"/cylinder_*.svg "$images"/rotate90_*.svg 2>/dev/null
