// fmt_fft_bf: one radix-2^2 SDF butterfly stage with its delay line
+incdir+rtl
rtl/fmt_fft_bf.v
rtl/fmt_fft_delay.v
