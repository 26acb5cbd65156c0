// fmt_fft_r22sdf: streaming radix-2^2 SDF FFT
+incdir+rtl
rtl/fmt_fft_r22sdf.v
rtl/fmt_fft_twiddle.v
-f rtl/filelists/fmt_fft_bf.f
