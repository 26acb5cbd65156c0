// fmt_rx_group_front: shared FFT front end of a column group
+incdir+rtl
rtl/fmt_rx_group_front.v
rtl/fmt_pair_split.v
rtl/fmt_rx_frame_win.v
-f rtl/filelists/fmt_fft_r22sdf.f
