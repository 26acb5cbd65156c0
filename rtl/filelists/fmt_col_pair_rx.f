// fmt_col_pair_rx: reference-only column-pair receiver (not part of fmt_core)
+incdir+rtl
rtl/ref/fmt_col_pair_rx.v
rtl/ref/fmt_accum.v
rtl/fmt_magnitude.v
-f rtl/filelists/fmt_rx_pair_front.f
