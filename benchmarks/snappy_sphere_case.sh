#!/usr/bin/env bash
# A snappyHexMesh case for the move benchmarks: a sphere of radius 0.3 (OpenFOAM's analytic
# searchableSphere, no surface file) cut out of the box [-1, 1]^3 of CELLS^3 hexahedra, the
# sphere's cells refined LEVEL times; patches "sphere" and "box". With the defaults (24, 2):
# 28,800 points, 23,376 cells of which 2,728 polyhedra. Needs Debian's openfoam. A controlDict,
# fvSchemes and fvSolution already in CASE_DIR/system are kept (the plugin test's, for its
# motion solver).
#
#   snappy_sphere_case.sh CASE_DIR [CELLS [LEVEL]]
set -euo pipefail
case_dir=$(realpath -m "$1")
cells=${2:-24}
level=${3:-2}
if [[ -f /usr/share/openfoam/etc/bashrc ]]; then
  # It reads unset variables and ends on a failing test.
  set +eu
  # shellcheck disable=SC1091
  source /usr/share/openfoam/etc/bashrc >/dev/null 2>&1
  set -eu
fi
command -v snappyHexMesh >/dev/null || { echo "snappy_sphere_case: snappyHexMesh not found (Debian's openfoam)" >&2; exit 1; }
mkdir -p "$case_dir/system" "$case_dir/constant" "$case_dir/0"
cd "$case_dir"
header='FoamFile { version 2.0; format ascii; class dictionary; object'
cat > system/blockMeshDict <<EOD
$header blockMeshDict; }
convertToMeters 1;
vertices ((-1 -1 -1) (1 -1 -1) (1 1 -1) (-1 1 -1) (-1 -1 1) (1 -1 1) (1 1 1) (-1 1 1));
blocks (hex (0 1 2 3 4 5 6 7) ($cells $cells $cells) simpleGrading (1 1 1));
edges ();
boundary (box { type wall; faces ((4 5 6 7) (0 3 2 1) (0 4 7 3) (1 2 6 5) (3 7 6 2) (0 1 5 4)); });
EOD
[[ -f system/controlDict ]] || cat > system/controlDict <<EOD
$header controlDict; }
application snappyHexMesh; startFrom startTime; startTime 0; stopAt endTime; endTime 1; deltaT 1;
writeControl timeStep; writeInterval 1; writeFormat ascii; writePrecision 17; writeCompression off;
timeFormat general; timePrecision 6; runTimeModifiable false;
EOD
[[ -f system/fvSchemes ]] || cat > system/fvSchemes <<EOD
$header fvSchemes; }
ddtSchemes { default steadyState; } gradSchemes { default Gauss linear; } divSchemes { default none; }
laplacianSchemes { default Gauss linear; } interpolationSchemes { default linear; } snGradSchemes { default corrected; }
EOD
[[ -f system/fvSolution ]] || echo "$header fvSolution; } solvers {}" > system/fvSolution
cat > system/snappyHexMeshDict <<EOD
$header snappyHexMeshDict; }
castellatedMesh true; snap true; addLayers false;
geometry { sphere { type searchableSphere; centre (0 0 0); radius 0.3; } }
castellatedMeshControls { maxLocalCells 1000000; maxGlobalCells 2000000; minRefinementCells 0; maxLoadUnbalance 0.1;
  nCellsBetweenLevels 2; features (); resolveFeatureAngle 30; refinementRegions {};
  refinementSurfaces { sphere { level ($level $level); patchInfo { type wall; } } }
  locationInMesh (0.71 0.73 0.69); allowFreeStandingZoneFaces true; }
snapControls { nSmoothPatch 3; tolerance 2.0; nSolveIter 30; nRelaxIter 5; nFeatureSnapIter 10;
  implicitFeatureSnap false; explicitFeatureSnap false; multiRegionFeatureSnap false; }
addLayersControls { relativeSizes true; layers {}; expansionRatio 1; finalLayerThickness 0.3; minThickness 0.1;
  nGrow 0; featureAngle 60; nRelaxIter 3; nSmoothSurfaceNormals 1; nSmoothNormals 3; nSmoothThickness 10;
  maxFaceThicknessRatio 0.5; maxThicknessToMedialRatio 0.3; minMedialAxisAngle 90; nBufferCellsNoExtrude 0;
  nLayerIter 50; }
meshQualityControls { maxNonOrtho 65; maxBoundarySkewness 20; maxInternalSkewness 4; maxConcave 80; minVol 1e-13;
  minTetQuality 1e-15; minArea -1; minTwist 0.02; minDeterminant 0.001; minFaceWeight 0.05; minVolRatio 0.01;
  minTriangleTwist -1; nSmoothScale 4; errorReduction 0.75; relaxed { maxNonOrtho 75; } }
mergeTolerance 1e-6;
EOD
blockMesh > log.blockMesh 2>&1 || { tail -5 log.blockMesh >&2; exit 1; }
snappyHexMesh -overwrite > log.snappy 2>&1 || { tail -20 log.snappy >&2; exit 1; }
