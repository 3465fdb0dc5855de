# Validation RMSE per epoch of the shipped recipe on flagsim-e2, grey frames against colour ones
# (`clothwind train ... --aux-tracks 2 --weight-average 0.999 [--colour]`, seeds 3, 2 and 4; 20
# epochs; the weight average's column val_rmse of each run's log.tsv).
# docs/sdn-experiments.md, "Colour". Regenerate from the repository root with
#   gnuplot docs/sdn_colour.gp
$curves << EOD
# epoch, then per seed 3, 2, 4: grey, colour (validation RMSE [m/s])
1 0.6552 0.6877 0.7013 0.6964 0.6676 0.6713
2 0.6317 0.6247 0.6093 0.6445 0.6182 0.6178
3 0.6122 0.5779 0.5991 0.6066 0.6011 0.5813
4 0.5949 0.5845 0.5742 0.5864 0.5779 0.5784
5 0.5877 0.5515 0.5511 0.5576 0.5938 0.6192
6 0.5757 0.5609 0.5431 0.5538 0.5534 0.5649
7 0.5458 0.5394 0.5487 0.5469 0.5424 0.5441
8 0.5381 0.5202 0.5555 0.5512 0.5369 0.5505
9 0.5229 0.5067 0.5187 0.5218 0.5328 0.5453
10 0.5195 0.4997 0.5078 0.5166 0.5038 0.5080
11 0.5161 0.4896 0.5054 0.5054 0.5004 0.5025
12 0.5161 0.4853 0.5070 0.5081 0.4962 0.4876
13 0.5116 0.4829 0.5011 0.4957 0.4930 0.4796
14 0.4993 0.4709 0.4979 0.4898 0.4775 0.4712
15 0.4880 0.4610 0.4971 0.4781 0.4669 0.4681
16 0.4916 0.4579 0.4934 0.4723 0.4632 0.4657
17 0.4837 0.4518 0.4888 0.4674 0.4628 0.4633
18 0.4760 0.4452 0.4820 0.4619 0.4609 0.4609
19 0.4712 0.4404 0.4801 0.4586 0.4552 0.4590
20 0.4682 0.4382 0.4799 0.4569 0.4535 0.4575
EOD
set terminal pngcairo size 900,560 font "DejaVu Sans,10"
set output "docs/sdn_colour.png"
set title "Validation RMSE per epoch: grey frames against colour (Y, Cr, Cb), flagsim-e2"
set xlabel "epoch (cosine learning rate from 1e-3 to 0)"
set ylabel "validation RMSE [m/s]"
set yrange [0.42:0.72]
set xrange [0.5:20.5]
set grid
set key top right
plot $curves using 1:2 with linespoints pt 6 lw 1.5 lc rgb "#7f9cc8" title "seed 3, grey", \
     $curves using 1:3 with linespoints pt 7 lw 2 lc rgb "#c0501a" title "seed 3, colour", \
     $curves using 1:4 with linespoints pt 4 lw 1.5 lc rgb "#4a6fa5" title "seed 2, grey", \
     $curves using 1:5 with linespoints pt 5 lw 2 lc rgb "#e07b39" title "seed 2, colour", \
     $curves using 1:6 with linespoints pt 8 lw 1.5 lc rgb "#1f3f73" title "seed 4, grey", \
     $curves using 1:7 with linespoints pt 9 lw 2 lc rgb "#f2a65a" title "seed 4, colour"
