# farm_lib.sh — sourced by the farm scripts (bash). The job description, OUTDIR/job.env, is a
# bash file of these variables, written by a submit script and read by every part and the merge:
#   OBSCURA_BIN          the obscura binary, as the nodes see it
#   OBSCURA_SCENE        the scene (.gltf), as the nodes see it
#   OBSCURA_OUTDIR       the job's folder on the shared file system: parts/, logs/, the merged image
#   OBSCURA_PARTS        number of parts (Slurm array tasks / Kubernetes completions)
#   OBSCURA_TILES        number of horizontal strips (PARTS is a multiple of it)
#   OBSCURA_SPP          samples per pixel of the whole frame
#   OBSCURA_OUTPUT       the merged image's file name in OBSCURA_OUTDIR (.exr or .png)
#   OBSCURA_RENDER_OPTS  bash array: further render options (--width, --height, --seed, --method ...)
#   OBSCURA_FARM_DIR     this folder (tools/farm), as the nodes see it
# Part k renders to OBSCURA_OUTDIR/parts/part-KKKK.exr with the arguments part_args.sh prints.

# This folder on this host (OBSCURA_FARM_DIR is where the nodes see it, perhaps a path in an image).
FARM_LIB_DIR=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

farm_die() { echo "${FARM_PROG:-farm}: $*" >&2; exit 2; }

# farm_part_args INDEX / farm_part_name INDEX — part_args.sh for the loaded job.
# farm_job_option OPTION VALUE — sets the job description's variable that OPTION names; the options
# both submit.sh take alike. False for any other option.
# shellcheck disable=SC2034 # the variables are the job description, read by the sourcing script
farm_job_option() {
  case $1 in
    --scene) OBSCURA_SCENE=$2 ;;
    --spp) OBSCURA_SPP=$2 ;;
    --parts) OBSCURA_PARTS=$2 ;;
    --tiles) OBSCURA_TILES=$2 ;;
    --outdir) OBSCURA_OUTDIR=$2 ;;
    --output) OBSCURA_OUTPUT=$2 ;;
    --bin) OBSCURA_BIN=$2 ;;
    --farm-dir) OBSCURA_FARM_DIR=$2 ;;
    *) return 1 ;;
  esac
}
# farm_check_job_options — the job options both submit.sh require, checked alike; a missing
# --tiles means strips only (TILES = PARTS).
farm_check_job_options() {
  local v
  for v in scene spp parts outdir; do
    local var=OBSCURA_${v^^}
    [ -n "${!var}" ] || farm_die "--$v is required (--help)"
  done
  OBSCURA_TILES=${OBSCURA_TILES:-$OBSCURA_PARTS}
  farm_check_numbers "$OBSCURA_PARTS" "$OBSCURA_TILES" "$OBSCURA_SPP"
  [[ $OBSCURA_OUTPUT =~ ^[^/]+\.(exr|png)$ ]] || farm_die "--output must be a file name ending in .exr or .png"
}
farm_part_args() { "$FARM_LIB_DIR/part_args.sh" "$1" "$OBSCURA_PARTS" "$OBSCURA_TILES" "$OBSCURA_SPP"; }
farm_part_name() { "$FARM_LIB_DIR/part_args.sh" --name "$1" "$OBSCURA_PARTS" "$OBSCURA_TILES" "$OBSCURA_SPP"; }

# farm_print_job_env — the OBSCURA_* variables above as bash assignments, quoted.
farm_print_job_env() {
  local v
  echo "# obscura farm job, written by ${FARM_PROG:-farm} on $(date -u +%Y-%m-%dT%H:%M:%SZ); bash syntax"
  for v in OBSCURA_BIN OBSCURA_SCENE OBSCURA_OUTDIR OBSCURA_PARTS OBSCURA_TILES OBSCURA_SPP \
           OBSCURA_OUTPUT OBSCURA_FARM_DIR; do
    printf '%s=%q\n' "$v" "${!v}"
  done
  printf 'OBSCURA_RENDER_OPTS=('
  for v in ${OBSCURA_RENDER_OPTS[@]+"${OBSCURA_RENDER_OPTS[@]}"}; do printf ' %q' "$v"; done
  printf ' )\n'
}

# farm_write_job_env FILE — farm_print_job_env into FILE, atomically.
farm_write_job_env() {
  farm_print_job_env >"$1.tmp.$$"
  mv -f "$1.tmp.$$" "$1"
}

# farm_load_job_env FILE — sources it and checks that the job is complete and consistent.
farm_load_job_env() {
  local file=$1 v
  [ -f "$file" ] || farm_die "no job description $file"
  OBSCURA_RENDER_OPTS=()
  # shellcheck disable=SC1090
  source "$file"
  for v in OBSCURA_BIN OBSCURA_SCENE OBSCURA_OUTDIR OBSCURA_PARTS OBSCURA_TILES OBSCURA_SPP \
           OBSCURA_OUTPUT OBSCURA_FARM_DIR; do
    [ -n "${!v:-}" ] || farm_die "$file does not set $v"
  done
  "$FARM_LIB_DIR/part_args.sh" 0 "$OBSCURA_PARTS" "$OBSCURA_TILES" "$OBSCURA_SPP" >/dev/null \
    || farm_die "$file: bad PARTS/TILES/SPP"
}

# farm_check_numbers PARTS TILES SPP — part_args.sh's checks, before anything is written.
farm_check_numbers() {
  "$FARM_LIB_DIR/part_args.sh" 0 "$1" "$2" "$3" >/dev/null || exit 2
}

# farm_part_files — the loaded job's part files that exist, one a line, by index. (Merging these
# rather than the folder leaves out anything else there, such as the hidden temporary file
# ".part-0003.tmp<pid>.exr" of a render killed while writing.)
farm_part_files() {
  local k f
  for ((k = 0; k < OBSCURA_PARTS; k++)); do
    printf -v f '%s/parts/part-%04d.exr' "$OBSCURA_OUTDIR" "$k"
    [ ! -e "$f" ] || echo "$f"
  done
}

# farm_missing_parts — prints the indices (ascending, one a line) of the loaded job's parts that
# are missing: those without a part file, and, when OBSCURA_BIN runs here, those that
# `obscura merge --list-missing` names (a line "--tile I/T --samples A:B" stands for every part of
# strip I whose sample range overlaps [A,B)).
farm_missing_parts() {
  local k f
  local -A absent=()
  for ((k = 0; k < OBSCURA_PARTS; k++)); do
    printf -v f '%s/parts/part-%04d.exr' "$OBSCURA_OUTDIR" "$k"
    [ -e "$f" ] || absent[$k]=1
  done
  if (( ${#absent[@]} < OBSCURA_PARTS )) && [ -x "$OBSCURA_BIN" ]; then
    local listing line ranges=$((OBSCURA_PARTS / OBSCURA_TILES)) r a b files
    mapfile -t files < <(farm_part_files)
    if listing=$("$OBSCURA_BIN" merge --list-missing "${files[@]}" 2>/dev/null); then
      while read -r line; do
        [ -n "$line" ] || continue
        if [[ $line =~ ^--tile\ ([0-9]+)/([0-9]+)\ --samples\ ([0-9]+):([0-9]+)$ ]] \
           && [ "${BASH_REMATCH[2]}" = "$OBSCURA_TILES" ]; then
          for ((r = 0; r < ranges; r++)); do
            a=$((r * OBSCURA_SPP / ranges)) b=$(((r + 1) * OBSCURA_SPP / ranges))
            if ((a < BASH_REMATCH[4] && BASH_REMATCH[3] < b)); then
              absent[$((r * OBSCURA_TILES + BASH_REMATCH[1]))]=1
            fi
          done
        else
          echo "${FARM_PROG:-farm}: warning: obscura merge --list-missing printed '$line'," \
               "not a strip of this job's $OBSCURA_TILES; going by part files alone" >&2
        fi
      done <<<"$listing"
    else
      echo "${FARM_PROG:-farm}: warning: '$OBSCURA_BIN merge --list-missing' failed here;" \
           "going by part files alone" >&2
    fi
  fi
  printf '%s\n' "${!absent[@]}" | sort -n | sed '/^$/d'
}

# farm_index_ranges — reads ascending indices (one a line), prints them as "0-3,7,9-10".
farm_index_ranges() {
  awk 'NR == 1 { s = p = $1; next }
       $1 == p + 1 { p = $1; next }
       { out = out (out == "" ? "" : ",") (s == p ? s : s "-" p); s = p = $1 }
       END { if (NR) print out (out == "" ? "" : ",") (s == p ? s : s "-" p) }'
}

# farm_expand_indices "0-3,7" — prints 0 1 2 3 7 (one a line); fails on anything else.
farm_expand_indices() {
  local item a b
  local -a items
  IFS=, read -r -a items <<<"$1"
  ((${#items[@]})) || return 1
  for item in "${items[@]}"; do
    if [[ $item =~ ^([0-9]{1,9})-([0-9]{1,9})$ ]]; then
      a=$((10#${BASH_REMATCH[1]})) b=$((10#${BASH_REMATCH[2]}))
      ((a <= b)) || return 1
      seq "$a" "$b"
    elif [[ $item =~ ^[0-9]{1,9}$ ]]; then
      echo $((10#$item))
    else
      return 1
    fi
  done
}
