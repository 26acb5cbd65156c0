// fmt_interp: sub-cell interpolation
+incdir+rtl
rtl/fmt_interp.v
rtl/fmt_interp_dly.v
rtl/fmt_interp_mul.v
rtl/fmt_interp_cordic.v
rtl/fmt_interp_div.v
rtl/fmt_interp_lg.v
rtl/fmt_interp_exp.v
rtl/fmt_interp_bias_rom.v
