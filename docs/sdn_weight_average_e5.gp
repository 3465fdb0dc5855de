# Validation RMSE per epoch of the shipped SDN's run on the whole of flagsim-e5 (`clothwind train
# ... --aux-tracks 2 --no-flip --weight-average 0.999`, seed 3, 20 epochs: runs/nfwa-e5c20): the
# weight average, whose best epoch ships, against the trained weights, which are the run before it
# (runs/nf-e5c20) epoch for epoch. From the run's log.tsv (val_rmse, raw_val_rmse).
# docs/sdn-experiments.md, "The weight average on the whole of e5". Regenerate from the repository root with
#   gnuplot docs/sdn_weight_average_e5.gp
$curves << EOD
# epoch, weight average, trained weights (validation RMSE [m/s], 2540 clips)
1 0.4738 0.6569
2 0.4381 0.8173
3 0.4467 0.5922
4 0.4161 1.1675
5 0.3990 0.4862
6 0.4018 0.4725
7 0.3947 0.4061
8 0.3996 0.4720
9 0.4050 0.4818
10 0.3910 0.4735
11 0.3749 0.4486
12 0.3646 0.3961
13 0.3564 0.3938
14 0.3511 0.3879
15 0.3445 0.3709
16 0.3418 0.3553
17 0.3397 0.3556
18 0.3379 0.3448
19 0.3387 0.3467
20 0.3389 0.3420
EOD
set terminal pngcairo size 900,560 font "DejaVu Sans,10"
set output "docs/sdn_weight_average_e5.png"
set title "Validation RMSE per epoch on flagsim-e5: the weight average against the trained weights"
set xlabel "epoch (cosine learning rate from 1e-3 to 0)"
set ylabel "validation RMSE [m/s]"
set yrange [0.32:0.70]
set xrange [0.5:20.5]
set grid
set key top right
set arrow from 0.5, 0.3420 to 20.5, 0.3420 nohead dt 2 lc rgb "#808080"
set label "model shipped before: 0.3420" at 1, 0.3365 tc rgb "#606060"
plot $curves using 1:3 with linespoints pt 6 lw 1.5 lc rgb "#9ab6d8" title "trained weights (the run shipped before)", \
     $curves using 1:2 with linespoints pt 7 lw 2 lc rgb "#1f4e9a" title "weight average 0.999 (best, epoch 18: shipped)"
