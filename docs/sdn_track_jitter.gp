# What a reader of the cloth's points must achieve: boosted trees on flagsim-e5's own tracks
# (scripts/track-oracle, docs/sdn-experiments.md "The exact tracks of FlagSim's own clips"),
# e5 test RMSE for one window against the jitter added to every point in every frame, in pixels
# of the SDN's 64-px input. Regenerate from the repository root with
#   gnuplot docs/sdn_track_jitter.gp
# Columns: jitter [px of 64], RMSE [m/s].
$motion << EOD
0 0.230
0.5 0.252
1 0.279
EOD
$positions << EOD
0 0.249
1 0.277
2 0.311
EOD
set terminal pngcairo size 760,480 font "DejaVu Sans,10"
set output "docs/sdn_track_jitter.png"
set title "How precisely a reader must find the flag's 8×6 points (flagsim-e5 test, one window)"
set xlabel "tracker jitter per point and frame [px of a 64-px frame]"
set ylabel "test RMSE [m/s]"
set xrange [-0.1:2.3]
set yrange [0.15:0.37]
set grid
set key top left
set arrow from graph 0, first 0.343 to graph 1, first 0.343 nohead dt 2 lw 2 lc rgb "#606060"
set label "shipped SDN 0.343" at 1.45, 0.349 tc rgb "#606060"
set arrow from graph 0, first 0.25 to graph 1, first 0.25 nohead dt 2 lw 2 lc rgb "#c00000"
set label "issue's target 0.25" at 1.45, 0.244 tc rgb "#c00000"
set arrow from graph 0, first 0.18 to graph 1, first 0.18 nohead dt 3 lw 1.5 lc rgb "#404040"
set label "paper 0.180" at 1.45, 0.174 tc rgb "#404040"
plot $motion using 1:2 with linespoints pt 7 lw 2 lc rgb "#1f5fbf" title "motion features (1056)", \
     $positions using 1:2 with linespoints pt 5 lw 2 lc rgb "#2e8b57" title "window-mean positions (96)"
