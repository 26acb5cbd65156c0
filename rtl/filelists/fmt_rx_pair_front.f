// fmt_rx_pair_front: despread + FFT front end of a column pair
+incdir+rtl
rtl/fmt_rx_pair_front.v
rtl/fmt_despread.v
rtl/fmt_pair_split.v
rtl/fmt_rx_frame_win.v
-f rtl/filelists/fmt_fft_r22sdf.f
