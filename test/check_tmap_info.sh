#!/usr/bin/env bash
# tmap_info: exact counts on the shipped maps; one error line and exit status 2 on malformed files.
set -u
bin="$1"; pkg="$2"
fail=0
check() { # file key expected
  got="$("$bin" "$1" | sed -n "s/^$2: //p")"
  if [ "$got" != "$3" ]; then echo "FAIL: $1 $2: got '$got', want '$3'"; fail=1; else echo "ok: $(basename "$1") $2 = $3"; fi
}
check "$pkg/config/maps/riseholme.tmap2" nodes 138
check "$pkg/config/maps/riseholme.tmap2" directed_edges 308
check "$pkg/config/maps/riseholme.tmap2" undirected_edges 154
check "$pkg/config/maps/riseholme.tmap2" lanes 12
check "$pkg/config/maps/riseholme.tmap2" components 1
"$bin" "$pkg/config/maps/riseholme.tmap2" | grep -q '^bbox: \[12\.4[0-9]*, -37\.[0-9]*, 31\.[45][0-9]*, 3\.0[0-9]*\]' \
  || { echo "FAIL: bbox line"; "$bin" "$pkg/config/maps/riseholme.tmap2"; fail=1; }
# The shipped map is the upstream file byte for byte: its sha256 is the one config/maps/README.md gives.
want="$(sed -n 's/^- sha256: `\([0-9a-f]\{64\}\)`$/\1/p' "$pkg/config/maps/README.md")"
got="$(sha256sum "$pkg/config/maps/riseholme.tmap2" | cut -d' ' -f1)"
if [ -z "$want" ] || [ "$got" != "$want" ]; then echo "FAIL: riseholme.tmap2 sha256 $got, README says '$want'"; fail=1
else echo "ok: riseholme.tmap2 sha256 matches config/maps/README.md"; fi
tmp="$(mktemp -d)"; trap 'rm -rf "$tmp"' EXIT
printf 'nodes:\n- node: {name: A, pose: {position: {x: 0, y: 0}}, edges: [{edge_id: A_B, node: B}]}\n' > "$tmp/missing_target.tmap2"
printf 'nodes:\n- node: {name: A, pose: {position: {x: oops, y: 0}}}\n' > "$tmp/bad_number.tmap2"
: > "$tmp/empty.tmap2"
printf '42\n' > "$tmp/scalar.tmap2"
for f in missing_target bad_number empty scalar nonexistent; do
  out="$("$bin" "$tmp/$f.tmap2" 2>&1 >/dev/null)"; rc=$?
  lines="$(printf '%s\n' "$out" | grep -c .)"
  if [ $rc -ne 2 ] || [ "$lines" -ne 1 ] || ! printf '%s' "$out" | grep -q "$tmp/$f.tmap2"; then
    echo "FAIL: $f: rc=$rc lines=$lines out='$out'"; fail=1
  else
    echo "ok: $f -> rc 2: $out"
  fi
done
printf '%s\n' "$("$bin" "$tmp/missing_target.tmap2" 2>&1)" | grep -q "node 'A'" || { echo "FAIL: node name missing"; fail=1; }
printf '%s\n' "$("$bin" "$tmp/bad_number.tmap2" 2>&1)" | grep -q "node.pose.position.x" || { echo "FAIL: field missing"; fail=1; }
# Bad inputs: a device never ends (tmap_info /dev/zero hung), a directory is no map, a 2 MB token must not be echoed.
python3 -c "print('nodes:\n- node: {name: A, pose: {position: {x: ' + 'x' * 2000000 + ', y: 0}}}')" > "$tmp/long_token.tmap2"
mkdir -p "$tmp/a_directory"
for f in /dev/zero "$tmp/a_directory" "$tmp/long_token.tmap2"; do
  out="$(timeout 60 "$bin" "$f" 2>&1 >/dev/null)"; rc=$?  # a hang is 124; 60 s: a loaded machine
  lines="$(printf '%s\n' "$out" | grep -c .)"
  if [ $rc -ne 2 ] || [ "$lines" -ne 1 ] || [ "${#out}" -gt 1000 ]; then
    echo "FAIL: $f: rc=$rc lines=$lines length=${#out} out='${out:0:300}'"; fail=1
  else
    echo "ok: $f -> rc 2: $out"
  fi
done
# rosrun finds the tool after `make` (rosrun skips every path below <package>/build/, so the devel space
# must live outside it: make puts it in build-devel/). The third argument is the devel space of this build.
devel="${3:-}"
if [ -n "$devel" ]; then
  case "$(cd "$devel" && pwd -P)/" in
    "$(cd "$pkg" && pwd -P)/build/"*) echo "FAIL: the devel space $devel is below $pkg/build/, where rosrun never looks (build with make)"; fail=1 ;;
    *) out="$(cd /tmp && bash -c "source '$devel/setup.bash' && rosrun picker_localisation tmap_info '$pkg/config/maps/riseholme.tmap2'" 2>&1)"
       if printf '%s\n' "$out" | grep -q '^nodes: 138$'; then echo "ok: rosrun picker_localisation tmap_info from the devel space"
       else echo "FAIL: rosrun tmap_info from the devel space: $out"; fail=1; fi ;;
  esac
fi
exit $fail
