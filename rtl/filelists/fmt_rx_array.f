// fmt_rx_array: the receive side (every column)
+incdir+rtl
rtl/fmt_rx_array.v
rtl/fmt_magnitude.v
-f rtl/filelists/fmt_rx_pair_front.f
-f rtl/filelists/fmt_rx_group_front.f
