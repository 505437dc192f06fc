#!/usr/bin/env bash
# part_args.sh [--name] INDEX PARTS TILES SPP
#
# The one part numbering of a farm render (Slurm array task id = Kubernetes completion index =
# INDEX). A job of PARTS parts cuts the frame into TILES horizontal strips and the SPP samples per
# pixel into PARTS/TILES ranges; part k renders strip k % TILES of sample range k / TILES.
# Range r of R is [r*SPP/R, (r+1)*SPP/R) (integer division): sizes differ by at most one sample.
#
# Prints the render arguments of part INDEX, e.g. "--tile 1/4 --samples 0:8", or with --name the
# part's file name, "part-0001.exr". Bad input: a message on stderr, exit 2.
set -euo pipefail

usage="usage: part_args.sh [--name] INDEX PARTS TILES SPP"
bad() { echo "part_args.sh: $*" >&2; echo "$usage" >&2; exit 2; }

name=0
if [ "${1:-}" = "--name" ]; then name=1; shift; fi
[ $# -eq 4 ] || bad "expected 4 arguments, got $#"
labels=(INDEX PARTS TILES SPP)
values=("$@")
for i in 0 1 2 3; do
  # Plain decimal only (no sign, no leading zeros, at most 9 digits): bash would read 010 as octal.
  [[ ${values[i]} =~ ^(0|[1-9][0-9]{0,8})$ ]] || bad "${labels[i]} must be a non-negative integer, got '${values[i]}'"
done
index=$1 parts=$2 tiles=$3 spp=$4
((parts >= 1)) || bad "PARTS must be at least 1"
((parts <= 10000)) || bad "PARTS must be at most 10000 (part file names have 4 digits)"
((tiles >= 1)) || bad "TILES must be at least 1"
((spp >= 1)) || bad "SPP must be at least 1"
((parts % tiles == 0)) || bad "PARTS ($parts) must be a multiple of TILES ($tiles)"
ranges=$((parts / tiles))
((ranges <= spp)) || bad "PARTS/TILES = $ranges sample ranges, more than SPP ($spp): some would be empty"
((index < parts)) || bad "INDEX ($index) must be below PARTS ($parts)"

if ((name)); then
  printf 'part-%04d.exr\n' "$index"
  exit 0
fi
tile=$((index % tiles))
range=$((index / tiles))
printf -- '--tile %d/%d --samples %d:%d\n' "$tile" "$tiles" $((range * spp / ranges)) $(((range + 1) * spp / ranges))
