#!/usr/bin/env bash
# Debian's OpenFOAM headers for the motion solver plugin (cmake/MeshmotionOpenFOAM.cmake).
# Debian ships OpenFOAM's libraries without headers, but its source package is in the same
# archive: this downloads it with a private apt configuration whose `deb-src` entries are the
# machine's own `deb` ones, extracts the libraries the plugin compiles against and gives each
# the flat lnInclude folder of links that OpenFOAM's wmake makes.
#
#   tools/openfoam-source.sh DIR     ->  DIR/src/<library>/lnInclude
set -euo pipefail
out=${1:?usage: openfoam-source.sh DIR}
libraries=(OpenFOAM OSspecific/POSIX finiteVolume meshTools dynamicMesh fvMotionSolver surfMesh fileFormats)
mkdir -p "$out"
out=$(cd "$out" && pwd)
if [[ -f "$out/src/.complete" ]]; then exit 0; fi
apt="$out/apt"
rm -rf "$apt" "$out/src"
mkdir -p "$apt/sources.list.d" "$apt/lists/partial" "$apt/cache/archives/partial" "$apt/download"
found=0
for f in /etc/apt/sources.list.d/*.sources; do
  [[ -f "$f" ]] || continue
  sed -E 's/^Types:.*/Types: deb-src/' "$f" > "$apt/sources.list.d/$(basename "$f")"
  found=1
done
if [[ -f /etc/apt/sources.list ]] && grep -qE '^deb ' /etc/apt/sources.list; then
  grep -E '^deb ' /etc/apt/sources.list | sed 's/^deb /deb-src /' > "$apt/sources.list.d/machine.list"
  found=1
fi
((found)) || { echo "openfoam-source.sh: no apt sources on this machine" >&2; exit 1; }
options=(-o Dir::Etc::SourceList=/dev/null -o "Dir::Etc::SourceParts=$apt/sources.list.d"
         -o "Dir::State::Lists=$apt/lists" -o "Dir::Cache=$apt/cache" -o APT::Sandbox::User=root)
apt-get -qq "${options[@]}" update
version=$(dpkg-query -W -f='${source:Version}' libopenfoam 2>/dev/null || true)
(cd "$apt/download" && apt-get -qq "${options[@]}" source --download-only "openfoam${version:+=$version}")
archive=$(ls "$apt/download"/openfoam_*.orig.tar.* | head -1)
patterns=()
for l in "${libraries[@]}"; do patterns+=("*/src/$l/*"); done
mkdir -p "$out/extract"
tar -xf "$archive" -C "$out/extract" --wildcards "${patterns[@]}"
mv "$out/extract"/*/src "$out/src"
rm -rf "$out/extract" "$apt"
for l in "${libraries[@]}"; do
  # One ln for all of a library's files (one per file took most of this script's time); a link
  # is named by its target's base name, as wmake's are.
  (cd "$out/src/$l" && mkdir -p lnInclude &&
   find . -path ./lnInclude -prune -o \( -name '*.H' -o -name '*.C' -o -name '*.h' \) -type f -printf '../%P\n' |
     xargs -r ln -sf -t lnInclude)
done
touch "$out/src/.complete"
