# How precisely the flag's mean shape must be known, and where the SDN's track head stands:
# e5 test RMSE for one window read by boosted trees from the 8x6 points' window-mean positions,
# against the rms error of those positions (per coordinate, pixels of the SDN's 64-px input).
# docs/sdn-experiments.md, "What the head knows of the points". Regenerate from the repository
# root with
#   gnuplot docs/sdn_head_positions.gp
# Columns: error of the window-mean positions [px of 64], RMSE [m/s].
# scripts/head-oracle --columns truth --targets positions [--position-noise N]: one centred
# window per training clip, noise that does not average out over the window.
$noise << EOD
0 0.251
0.25 0.299
0.5 0.353
1 0.444
EOD
# scripts/track-oracle --features shape [--track-noise J]: 8 windows and their mirrors per
# training clip, jitter J independent per frame, so the window mean errs by J / sqrt(30).
$jitter << EOD
0 0.249
0.183 0.277
0.365 0.311
EOD
# The SDN's own head (runs/aux2-e5c28-s3, clothwind eval --track-head): x 1.286, y 0.903 px,
# rms 1.11; its positions read by the same trees (--columns predicted --targets positions).
$head << EOD
1.11 0.423
EOD
set terminal pngcairo size 760,480 font "DejaVu Sans,10"
set output "docs/sdn_head_positions.png"
set title "How precisely the flag's mean shape must be known (flagsim-e5 test, one window)"
set xlabel "rms error of the 8×6 points' window-mean positions [px of a 64-px frame]"
set ylabel "test RMSE [m/s]"
set xrange [-0.05:1.25]
set yrange [0.15:0.48]
set grid
set key top left
set arrow from graph 0, first 0.343 to graph 1, first 0.343 nohead dt 2 lw 2 lc rgb "#606060"
set label "SDN aux2-e5c20 (shipped to 2026-12-03) 0.343" at 0.55, 0.336 tc rgb "#606060"
set arrow from graph 0, first 0.25 to graph 1, first 0.25 nohead dt 2 lw 2 lc rgb "#c00000"
set label "issue's target 0.25" at 0.9, 0.243 tc rgb "#c00000"
set arrow from graph 0, first 0.18 to graph 1, first 0.18 nohead dt 3 lw 1.5 lc rgb "#404040"
set label "paper 0.180" at 0.9, 0.173 tc rgb "#404040"
set label "the SDN's head" at 0.82, 0.425 tc rgb "#c05000"
plot $noise using 1:2 with linespoints pt 7 lw 2 lc rgb "#1f5fbf" title "exact positions + noise (one window a clip)", \
     $jitter using 1:2 with linespoints pt 5 lw 2 lc rgb "#2e8b57" title "tracks jittered per frame (8 windows a clip)", \
     $head using 1:2 with points pt 9 ps 2 lc rgb "#c05000" title "the head's positions"
