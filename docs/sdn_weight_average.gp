# Validation RMSE per epoch of the shipped recipe on flagsim-e2 with a weight average
# (`clothwind train ... --aux-tracks 2 --weight-average 0.999`, seeds 3 and 2; 20 epochs): the
# average's against the trained weights' own, from each run's log.tsv (val_rmse, raw_val_rmse).
# docs/sdn-experiments.md, "Averaged weights". Regenerate from the repository root with
#   gnuplot docs/sdn_weight_average.gp
# It also draws docs/sdn_weight_average_e5.png: the shipped SDN's run on the whole of flagsim-e5
# (`... --no-flip --weight-average 0.999`, runs/nfwa-e5c20), whose trained weights are the run
# shipped before it (runs/nf-e5c20) epoch for epoch; docs/sdn-experiments.md, "The weight average
# on the whole of e5".
$curves << EOD
# epoch, seed 3: average, trained weights; seed 2: average, trained weights (validation RMSE [m/s])
1 0.6552 1.7139 0.7013 0.7399
2 0.6317 0.6948 0.6093 0.6378
3 0.6122 0.8253 0.5991 0.6704
4 0.5949 1.0443 0.5742 0.7933
5 0.5877 0.7766 0.5511 1.2108
6 0.5757 0.8740 0.5431 0.5965
7 0.5458 0.6070 0.5487 0.7407
8 0.5381 0.5699 0.5555 0.9566
9 0.5229 0.7161 0.5187 0.5646
10 0.5195 0.6092 0.5078 0.5242
11 0.5161 0.6090 0.5054 0.6053
12 0.5161 0.5806 0.5070 0.6628
13 0.5116 0.5423 0.5011 0.4981
14 0.4993 0.5150 0.4979 0.5084
15 0.4880 0.5020 0.4971 0.5272
16 0.4916 0.5177 0.4934 0.5052
17 0.4837 0.4725 0.4888 0.4793
18 0.4760 0.4893 0.4820 0.5021
19 0.4712 0.4730 0.4801 0.4840
20 0.4682 0.4686 0.4799 0.4803
EOD
set terminal pngcairo size 900,560 font "DejaVu Sans,10"
set output "docs/sdn_weight_average.png"
set title "Validation RMSE per epoch: the weight average against the trained weights (flagsim-e2)"
set xlabel "epoch (cosine learning rate from 1e-3 to 0)"
set ylabel "validation RMSE [m/s]"
set yrange [0.44:1.0]
set xrange [0.5:20.5]
set grid
set key top right
plot $curves using 1:3 with linespoints pt 6 lw 1.5 lc rgb "#9ab6d8" title "seed 3, trained weights", \
     $curves using 1:2 with linespoints pt 7 lw 2 lc rgb "#1f4e9a" title "seed 3, weight average", \
     $curves using 1:5 with linespoints pt 4 lw 1.5 lc rgb "#f2b48a" title "seed 2, trained weights", \
     $curves using 1:4 with linespoints pt 5 lw 2 lc rgb "#c0501a" title "seed 2, weight average"

$e5 << EOD
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
set output "docs/sdn_weight_average_e5.png"
set title "Validation RMSE per epoch on flagsim-e5: the weight average against the trained weights"
set yrange [0.32:0.70]
set arrow from 0.5, 0.3420 to 20.5, 0.3420 nohead dt 2 lc rgb "#808080"
set label "model shipped before: 0.3420" at 1, 0.3365 tc rgb "#606060"
plot $e5 using 1:3 with linespoints pt 6 lw 1.5 lc rgb "#9ab6d8" title "trained weights (the run shipped before)", \
     $e5 using 1:2 with linespoints pt 7 lw 2 lc rgb "#1f4e9a" title "weight average 0.999 (best, epoch 18: shipped)"
