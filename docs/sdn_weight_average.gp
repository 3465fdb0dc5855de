# Validation RMSE per epoch of the shipped recipe on flagsim-e2 with a weight average
# (`clothwind train ... --aux-tracks 2 --weight-average 0.999`, seeds 3 and 2; 20 epochs): the
# average's against the trained weights' own, from each run's log.tsv (val_rmse, raw_val_rmse).
# docs/sdn-experiments.md, "Averaged weights". Regenerate from the repository root with
#   gnuplot docs/sdn_weight_average.gp
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
