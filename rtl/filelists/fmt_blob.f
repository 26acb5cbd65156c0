// fmt_blob: connected-region (palm) detector
+incdir+rtl
rtl/fmt_blob.v
rtl/fmt_div.v
rtl/fmt_sorted_list.v
