// fmt_localmax: local maxima of the heat map
+incdir+rtl
rtl/fmt_localmax.v
rtl/fmt_sorted_list.v
