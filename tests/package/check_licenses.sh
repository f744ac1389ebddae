#!/usr/bin/env bash
# The libraries an artifact links, against the inventory of docs/licenses.md (its table "Linked
# libraries": the library in backticks in the first cell, the artifacts that link it in the second).
# usage: check_licenses.sh INVENTORY KEY FILE...          every library FILE needs (ELF NEEDED, or
#                                                        the DLL imports of a PE file) is a row
#                                                        naming KEY
#        check_licenses.sh INVENTORY --bundled KEY DIR   every shared library in DIR but the
#                                                        project's own is a row naming KEY
set -euo pipefail
inventory=$1
shift
bundled=0
if [ "$1" = --bundled ]; then
  bundled=1
  shift
fi
key=$1
shift
[ -f "$inventory" ] || { echo "licenses: no inventory $inventory" >&2; exit 1; }

# "library<TAB>key,key,..." for each row of the table (libraries lower-case: DLL names are not
# case-sensitive, and no ELF name here has capitals)
rows=$(sed -nE 's/^\| `([^`]+)` \| ([^|]+) \|.*/\1\t\2/p' "$inventory" | tr 'A-Z' 'a-z' | tr -d ' ')
[ -n "$rows" ] || { echo "licenses: $inventory has no table of linked libraries" >&2; exit 1; }

# the libraries FILE asks the loader for
needed() {
  local objdump=objdump
  if [ "$(head -c 2 "$1")" = MZ ]; then
    objdump=$(command -v x86_64-w64-mingw32-objdump || echo objdump)
    "$objdump" -p "$1" | sed -nE 's/^\s*DLL Name: (.*)$/\1/p'
  else
    "$objdump" -p "$1" | awk '$1 == "NEEDED" { print $2 }'
  fi
}

missing=0
check() {
  local library=$1 what=$2 lower
  lower=$(tr 'A-Z' 'a-z' <<<"$library")
  if ! awk -F'\t' -v lib="$lower" -v key="$key" \
      '$1 == lib { n = split($2, keys, ","); for (i = 1; i <= n; ++i) if (keys[i] == key) found = 1 }
       END { exit !found }' <<<"$rows"; then
    echo "licenses: $what: $library is not in $(basename "$inventory") for '$key' (add its row: licence and what it means)" >&2
    missing=$((missing + 1))
  fi
}

if [ "$bundled" = 1 ]; then
  dir=$1
  [ -d "$dir" ] || { echo "licenses: no folder $dir" >&2; exit 1; }
  count=0
  while IFS= read -r file; do
    case $(basename "$file") in libuh.so | uh.dll) continue ;; esac
    check "$(basename "$file")" "$dir"
    count=$((count + 1))
  done < <(find "$dir" -maxdepth 1 -type f \( -name '*.so*' -o -name '*.dll' \) -not -name '*.meta')
  echo "licenses: $count libraries bundled in $dir checked for '$key'"
else
  for file in "$@"; do
    [ -f "$file" ] || { echo "licenses: no $file" >&2; exit 1; }
    list=$(needed "$file")
    [ -n "$list" ] || { echo "licenses: $file names no library (not a linked ELF or PE file?)" >&2; exit 1; }
    while IFS= read -r library; do check "$library" "$(basename "$file")"; done <<<"$list"
    echo "licenses: $(wc -l <<<"$list") libraries of $(basename "$file") checked for '$key'"
  done
fi
[ "$missing" = 0 ] || exit 1
