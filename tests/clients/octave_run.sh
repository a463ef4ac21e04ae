#!/bin/sh
# Runs a MATLAB/Octave controller function under GNU Octave with a command line's
# arguments, as the other languages' controllers are run by the test harnesses:
#   octave_run.sh DIR FUNCTION ARG...   ->   octave --path DIR --eval "FUNCTION('ARG', ...)"
# (each ARG single-quoted, its quotes doubled). DIR holds the .m files (<build>/octave).
# Octave exits 0 when the function returns, 1 on an error.
dir=$1
fn=$2
shift 2
args=""
for a in "$@"; do
  q=$(printf '%s' "$a" | sed "s/'/''/g")
  args="$args${args:+, }'$q'"
done
exec octave --no-gui --quiet --no-window-system --no-init-file --path "$dir" --eval "$fn($args)"
