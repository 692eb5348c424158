#!/usr/bin/env bash
# Every recording in test/data is the upstream file byte for byte: its sha256 is the one test/data/README.md
# gives, and every file in test/data is named in that README (no unlisted data, no listed file missing).
# usage: check_test_data.sh PACKAGE_DIR
set -u
data="$1/test/data"
readme="$data/README.md"
fail=0
n=0
while IFS='|' read -r _ file _ _ _ _ _ sum _; do
  file="$(echo "$file" | tr -d ' `')"; sum="$(echo "$sum" | tr -d ' `')"
  [ -n "$sum" ] || continue
  n=$((n + 1))
  got="$(sha256sum "$data/$file" 2>/dev/null | cut -d' ' -f1)"
  if [ "$got" = "$sum" ]; then echo "ok: $file"; else echo "FAIL: $file: sha256 '$got', README says $sum"; fail=1; fi
done < <(grep '^| `' "$readme")
[ "$n" -ge 3 ] || { echo "FAIL: only $n checksums read from $readme"; fail=1; }
while IFS= read -r f; do
  rel="${f#"$data"/}"
  grep -q "^| \`$rel\` |" "$readme" || { echo "FAIL: $rel is not listed in test/data/README.md"; fail=1; }
done < <(find "$data" -type f ! -name README.md)
exit $fail
