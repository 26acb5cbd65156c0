# XST options of the XC5VSX95T build, sourced into the ISE project that edalize writes
# (fpga/xc5vsx95t.core, fileset xst_opts).
#
# Keep Hierarchy = Soft: XST maps every module on its own (the hierarchy is dropped again
# for map and par).  `make timing` checks the LUT depth with each module mapped on its own
# too (scripts/timing.py); a flat mapping may spend the slack of one block's paths on area
# up to the delay of the slowest carry path elsewhere (docs/timing.md), which the
# per-block check would not see.  The block boundaries of fmt_core are registered, so
# little is lost to the kept boundaries.
project set "Keep Hierarchy" "Soft" -process "Synthesize - XST"
