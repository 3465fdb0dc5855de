# The window oracle's learning curve beside the SDN's (docs/sdn-experiments.md, "The oracle on
# three times the simulations" and "More simulations are a lever"): one 30-frame window's RMSE
# against the simulations trained on, through Table 2's cameras unless marked 3-D; the oracle
# reads 19.2 s of each simulation unless marked 2.4 s. Regenerate
# from the repository root with
#   gnuplot docs/sdn_oracle_curve.gp
# Oracle columns: simulations trained on, RMSE [m/s] (boosted trees on exact point tracks).
$oracle54 << EOD
80 0.338
120 0.317
140 0.316
240 0.282
360 0.271
420 0.270
EOD
$oracle86 << EOD
140 0.296
240 0.271
420 0.257
EOD
$oracle3d << EOD
140 0.186
420 0.146
EOD
# The same oracle (5×4) trained and tested on each simulation's first 2.4 s only, as FlagSim
# renders them (`--train-seconds 2.4 --test-seconds 2.4`); every other oracle point saw 19.2 s.
$oracle24 << EOD
420 0.391
EOD
# The SDN (64 px, width 48, phase steps) on e2's test split: simulations in its training split
# (70 % of 1500, 3000, 4500, 6000), RMSE [m/s] (`ph`, `e3ph`, `e4ph`, `e5c`).
$sdn << EOD
1050 0.439
2100 0.424
3150 0.385
4200 0.380
EOD
set terminal pngcairo size 900,560 font "DejaVu Sans,10"
set output "docs/sdn_oracle_curve.png"
set title "One window's wind RMSE against the simulations trained on"
set xlabel "simulations in the training set"
set ylabel "RMSE [m/s]"
set logscale x
set xrange [60:6000]
set yrange [0.1:0.5]
set grid
set key bottom right
set arrow from graph 0, first 0.25 to graph 1, first 0.25 nohead dt 2 lw 2 lc rgb "#c00000"
set label "issue's target 0.25" at 70, 0.243 tc rgb "#c00000"
set arrow from graph 0, first 0.18 to graph 1, first 0.18 nohead dt 3 lw 1.5 lc rgb "#404040"
set label "paper's SDN 0.180" at 70, 0.173 tc rgb "#404040"
plot $oracle54 with linespoints pt 7 lw 2 lc rgb "#1f77b4" title "oracle, 5×4 exact points through the camera", \
     $oracle86 with linespoints pt 5 lw 2 lc rgb "#2ca02c" title "oracle, 8×6 exact points through the camera", \
     $oracle3d with linespoints pt 9 lw 2 lc rgb "#9467bd" title "oracle, 5×4 exact points in 3-D (no camera)", \
     $oracle24 with points pt 7 ps 1.6 lc rgb "#d62728" title "oracle, 5×4, 2.4 s per simulation (FlagSim's)", \
     $sdn with linespoints pt 13 lw 2 lc rgb "#e07000" title "SDN, 64 px, width 48, 2.4 s per simulation (e2 test)"
