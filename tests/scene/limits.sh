#!/bin/bash
# Hostile scene files are refused quickly, by a limit that the message names, before a
# tree of their size is built: huge mappings and sequences, too many nodes, deep nesting,
# long scalars, files larger than a scene can be, directories. Each case is generated
# here (the large ones would bloat the repository) and checked by expect_error.sh: exit
# 2, one line on stderr, nothing run. Usage: limits.sh LAGSIMD EXPECT_ERROR_SH
set -u
lagsimd=$1 expect=$2
fail=0
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
e() { "$expect" "$lagsimd" "$@" || fail=1; }

# 100 000 keys in one mapping (about 1 MB, under the file size limit): once 47 s of CPU
# in a quadratic duplicate-key check; now refused at the 1001st key.
awk 'BEGIN { print "model: dipc"; for (i = 0; i < 100000; i++) printf "k%d: 1\n", i }' > "$tmp/many_keys.yaml"
e "$tmp/many_keys.yaml" --expect "$tmp/many_keys.yaml:1001:1: more than 1000 keys in one mapping: this is the limit" --

# 400 000 items in one sequence (about 800 kB)
awk 'BEGIN { printf "model: dipc\ninitial:\n  q: [0"; for (i = 1; i < 400000; i++) printf ",0"; print "]" }' > "$tmp/long_seq.yaml"
e "$tmp/long_seq.yaml" --expect "$tmp/long_seq.yaml:3:2007: more than 1000 items in one sequence: this is the limit" --

# a file larger than a scene may be: refused before it is parsed
awk 'BEGIN { printf "model: dipc\ninitial:\n  q: [0"; for (i = 1; i < 1100000; i++) printf ",0"; print "]" }' > "$tmp/huge.yaml"
e "$tmp/huge.yaml" --expect "$tmp/huge.yaml: larger than 1048576 bytes, the limit for a scene file" --

# more nodes than a scene may have, each mapping under its own limit
awk 'BEGIN { print "model: dipc"; for (m = 0; m < 6; m++) { printf "x%d:\n", m; for (i = 0; i < 1000; i++) printf "  k%d: 1\n", i } }' > "$tmp/many_nodes.yaml"
e "$tmp/many_nodes.yaml" --expect "more than 10000 YAML nodes" --expect "this is the limit" --

# nesting deeper than the limit
awk 'BEGIN { printf "model: dipc\nx: "; for (i = 0; i < 40; i++) printf "["; for (i = 0; i < 40; i++) printf "]"; print "" }' > "$tmp/deep.yaml"
e "$tmp/deep.yaml" --expect "$tmp/deep.yaml:2:35: nesting deeper than 32 levels: this is the limit" --

# a scalar longer than the limit
awk 'BEGIN { printf "model: dipc\nlcm:\n  prefix: "; for (i = 0; i < 5000; i++) printf "A"; print "" }' > "$tmp/long_scalar.yaml"
e "$tmp/long_scalar.yaml" --expect "$tmp/long_scalar.yaml:3:11: a scalar of 5000 bytes: at most 4096 is the limit" --

# a --set value under the limits of one argument (128 kB on Linux) but over the items'
big=$(awk 'BEGIN { printf "["; for (i = 0; i < 60000; i++) printf "0,"; printf "0]" }')
printf "model: dipc\n" > "$tmp/ok.yaml"
e "$tmp/ok.yaml" --expect "--set initial.q: more than 1000 items in one sequence: this is the limit" -- --set "initial.q=$big"

# a directory is not a scene file
mkdir "$tmp/dir.yaml"
e "$tmp/dir.yaml" --expect "$tmp/dir.yaml: is a directory, not a scene file" --
exit $fail
