#!/usr/bin/env bash
# The footing's run time against error with `[mesh.adapt]`: bench/adapt_study.sh footing (the
# settings, measures and outputs are described there: bench/results/footing-adapt.csv and
# footing-adapt.commands).
#
# Usage: FACTOR=2 STEPS=100 RANKS=1 ADAPT='{h_min=0.125,h_max=1.0}' bench/adapt_footing.sh
exec "$(dirname "$0")/adapt_study.sh" footing "$@"
