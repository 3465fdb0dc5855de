# The "Levers at a glance" table of docs/sdn.md as a picture: every measured change to the SDN,
# its control's test RMSE and its own (one window), coloured by verdict. Figures and commands
# behind each row: docs/sdn-experiments.md. Regenerate from the repository root with
#   gnuplot docs/sdn_levers.gp
# Columns: row, control [m/s], change [m/s], verdict (0 shipped, 1 no lever, 2 not a product
# figure: other cameras or a leaky split), label.
$levers << EOD
1 0.599 0.526 0 "weight decay 1e-4, width 48 (e2)"
2 0.526 0.467 0 "whole frames, no multi-scale crop (e2)"
3 0.467 0.439 0 "phase steps (e2)"
4 0.439 0.380 0 "1500 → 6000 simulations (e2 test)"
5 0.599 0.598 1 "mirror test-time augmentation (e2)"
6 0.439 0.444 1 "far phase step (e2)"
7 0.439 0.434 1 "optical flow at 128 px (e2)"
8 0.463 0.454 1 "mode shape (e2)"
9 0.463 0.452 1 "coordinate maps (e2)"
10 0.463 0.460 1 "known fabric (e2 simulations)"
11 0.463 0.420 1 "auxiliary track head (e2, 2 seeds)"
12 0.398 0.392 1 "auxiliary track head (e5, 10 epochs)"
13 0.383 0.354 0 "auxiliary track head (e5, 20 epochs, 2 seeds)"
14 0.354 0.343 0 "auxiliary head at weight 2 (e5, 20 epochs)"
15 0.343 0.354 1 "auxiliary head at weight 4 (e5, 20 epochs)"
16 0.419 0.431 1 "the head also regresses phases (e2)"
17 0.419 0.421 1 "the head also regresses metres, --aux-world (e2)"
18 0.414 0.412 1 "no stem pool (e3)"
19 0.414 0.407 1 "128-px spectra pooled (e3)"
20 0.420 0.394 1 "128-px spectra pooled, with the head (e2, 2 seeds)"
21 0.396 0.385 1 "128-px spectra pooled, with the head (e3)"
22 0.437 0.429 1 "weight average (e2, 4 paired runs)"
23 0.429 0.410 1 "colour input: Y, Cr, Cb (e2, 3 seeds)"
24 0.343 0.344 1 "colour + weight average (e5, one run; validation better)"
25 0.343 0.345 1 "96-px input with the head (e5; validation better)"
26 0.343 0.368 1 "hidden layer in the wind head (e5)"
27 0.343 0.343 1 "96 px + weight average (e5; validation better)"
28 0.343 0.364 1 "ten frames beside the spectra (e5)"
29 0.343 0.340 1 "28 epochs with the head (e5; validation better)"
30 0.340 0.356 1 "trees on the head's outputs for the wind head (e5)"
31 0.509 0.487 1 "heat maps for the points (988 e2 simulations; validation worse)"
32 0.383 0.373 1 "width 64 (e5)"
33 0.383 0.377 1 "60 frames at once (e5)"
34 0.383 0.380 1 "26 epochs (e5)"
35 0.383 0.365 1 "96-px input, validation tied (e5)"
36 0.565 0.541 1 "224 px on a GPU (800 simulations)"
37 0.639 0.629 1 "224 px on a GPU (311 simulations)"
38 0.451 0.433 1 "128-px spectra + head, GPU (1000 sims, 3 seeds)"
39 0.478 0.518 1 "128-px spectra + head, GPU (490 sims, 2 seeds)"
40 0.435 0.411 1 "1 view of 4× the simulations (e5)"
41 0.411 0.383 1 "1 → 4 views, training grown (e5)"
42 0.439 0.359 2 "cameras level with the flag (e2 simulations)"
43 0.456 0.384 2 "split per clip, a leak (same clips)"
44 0.507 0.487 1 "no flips in training (988 e2 simulations, 3 seed pairs)"
45 0.444 0.407 1 "no flips in training (1093 e5 training simulations, 20 epochs)"
46 0.340 0.347 1 "no flips, 3206 e5 sims, against shipped (4167, flips)"
47 0.343 0.334 0 "no flips in training (all of e5, 20 epochs)"
48 0.334 0.329 0 "weight average on the no-flip run (all of e5, paired)"
49 0.329 0.314 0 "96-px input, width 32, with the weight average, no flips (all of e5)"
50 0.314 0.318 1 "112-px input at width 24 instead of 96 at 32 (all of e5; tie)"
EOD
set terminal pngcairo size 1250,900 font "DejaVu Sans,10"
set output "docs/sdn_levers.png"
set title "What each measured change did to the SDN's test RMSE (one window; arrow: control → change)"
set xlabel "test RMSE [m/s]"
set xrange [0.15:0.66]
# One row per measured change: the rows set the y range and where the reference lines are labelled.
stats $levers using 1 nooutput
rows = STATS_records
set yrange [rows + 1.2:0.3]
set ytics out nomirror
set grid xtics
unset key
set arrow from 0.25, graph 0 to 0.25, graph 1 nohead dt 2 lw 2 lc rgb "#c00000"
set label "issue's target 0.25" at 0.252, rows + 0.85 tc rgb "#c00000"
set arrow from 0.18, graph 0 to 0.18, graph 1 nohead dt 3 lw 1.5 lc rgb "#404040"
set label "paper 0.180" at 0.178, rows + 0.85 right tc rgb "#404040"
# What the pixels hold: boosted trees on the exact tracks of flagsim-e5's own clips (scripts/track-oracle).
set arrow from 0.230, graph 0 to 0.230, graph 1 nohead dt 3 lw 1.5 lc rgb "#1f5fbf"
set label "exact tracks of e5's clips 0.230" at 0.232, 0.62 tc rgb "#1f5fbf"
set label "shipped" at graph 0.74, 0.42 tc rgb "#2e8b57"
set label "no lever (a tie, or e2 only)" at graph 0.74, 0.38 tc rgb "#808080"
set label "not a product figure" at graph 0.74, 0.34 tc rgb "#e07000"
colour(c) = c == 0 ? 0x2e8b57 : (c == 1 ? 0x808080 : 0xe07000)
plot $levers using 2:1:($3-$2):(0):(colour($4)):ytic(5) with vectors head filled size 0.008,20 lw 2 lc rgb variable, \
     $levers using 2:1:(colour($4)) with points pt 7 ps 0.8 lc rgb variable
