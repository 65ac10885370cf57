#!/usr/bin/env bash
# The README's worked example, run as written: the block between its readme-example markers, executed in a
# folder laid out like the repository (build/, config/, data/, scripts/), must succeed and print every line
# the README quotes between its readme-output markers (runs of spaces squeezed). And every config key the
# README names in backticks (`section.key` or `section.key: value`, section one of config/default.yaml's) is
# a key of that file.
# Usage: readme_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
src=$2
work=$(mktemp -d /tmp/gins_readme.XXXXXX)
trap 'cd / && rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
cd "$work"
ln -s "$build" build
for d in config data scripts; do ln -s "$src/$d" "$d"; done
block() { sed -n "/<!-- $1:begin -->/,/<!-- $1:end -->/p" "$src/README.md" | sed '/^```/d; /^<!--/d'; }
squeeze() { sed 's/[[:space:]]\+/ /g; s/^ //; s/ $//'; }

block readme-example >example.sh
grep -q 'gins run' example.sh || fail "no worked example between the README's readme-example markers"
bash -euo pipefail example.sh >example.out 2>&1 || { cat example.out; fail "the README's worked example failed"; }
squeeze <example.out >printed.txt
block readme-output | squeeze | grep -v '^$' >quoted.txt || true
[ -s quoted.txt ] || fail "no quoted output between the README's readme-output markers"
while IFS= read -r line; do
  grep -qxF -- "$line" printed.txt || { cat example.out; fail "the README quotes a line the example does not print: $line"; }
done <quoted.txt

awk '/^[a-z_]+:/ {s = $1; sub(":", "", s)} /^  [a-z_0-9]+:/ {k = $1; sub(":", "", k); print s "." k}' \
  "$src/config/default.yaml" | sort -u >keys.txt
sections=$(cut -d. -f1 keys.txt | sort -u | paste -sd'|')
grep -o '`[a-z_]\+\.[a-z_0-9]\+[`:]' "$src/README.md" | tr -d '`:' | sort -u | { grep -E "^($sections)\." || true; } >named.txt
[ -s named.txt ] || fail "the README names no config key (the scan sees none)"
while read -r key; do
  grep -qxF "$key" keys.txt || fail "the README names $key, which config/default.yaml does not have"
done <named.txt
echo "README: the worked example ran as written; $(wc -l <quoted.txt) quoted lines printed," \
  "$(wc -l <named.txt) config keys found"
