# The paper's input (224 px, width 64) against the shipped recipe (64 px, width 48) as the
# training simulations grow, both trained on a GPU for 20 epochs (docs/sdn.md, "A data curve on a
# GPU"): one 30-frame window's test RMSE against the simulations in the training split. Regenerate
# from the repository root with
#   gnuplot docs/sdn_gpu_curve.gp
# Columns: training simulations, RMSE [m/s] one window, three windows. 76/161/311: one lease's
# dataset (2026-11-27, H200) and its first 150 and 300 simulations, all tested on that dataset's
# 829 test clips (208 simulations); 426: the earlier lease's 800 simulations (2026-11-27, H100),
# tested on its own 1140 clips.
$c64 << EOD
76 0.937 0.879
161 0.707 0.651
311 0.639 0.573
EOD
$p224 << EOD
76 0.842 0.776
161 0.665 0.584
311 0.629 0.560
EOD
$c64_h100 << EOD
426 0.565 0.492
EOD
$p224_h100 << EOD
426 0.558 0.474
EOD
# The shipped recipe on the CPU, flagsim-e2 test (`ph`, `e3ph`, `e4ph`, `e5c`; 40/20 epochs).
$cpu << EOD
1050 0.439
2100 0.424
3150 0.385
4200 0.380
EOD
set terminal pngcairo size 900,560 font "DejaVu Sans,10"
set output "docs/sdn_gpu_curve.png"
set title "224 px against 64 px as the training simulations grow (one 30-frame window, test RMSE)"
set xlabel "simulations in the training set"
set ylabel "RMSE [m/s]"
set logscale x
set xrange [60:6000]
set yrange [0.2:1.0]
set grid
set key top right
set arrow from graph 0, first 0.25 to graph 1, first 0.25 nohead dt 2 lw 2 lc rgb "#c00000"
set label "issue's target 0.25" at 70, 0.235 tc rgb "#c00000"
plot $c64 using 1:2 with linespoints lw 2 pt 7 lc rgb "#1f77b4" title "64 px, width 48 (GPU, one lease's test split)", \
     $p224 using 1:2 with linespoints lw 2 pt 5 lc rgb "#d62728" title "224 px, width 64 (GPU, same clips)", \
     $c64_h100 using 1:2 with points pt 6 ps 1.5 lc rgb "#1f77b4" title "64 px, earlier lease (own test split)", \
     $p224_h100 using 1:2 with points pt 4 ps 1.5 lc rgb "#d62728" title "224 px, earlier lease (own test split)", \
     $cpu using 1:2 with linespoints lw 1.5 dt 2 pt 9 lc rgb "#404040" title "64 px on the CPU, flagsim-e2 test (e2-e5)"
