// fmt_tx: DDS bank + PN chip generator
+incdir+rtl
rtl/fmt_tx.v
rtl/fmt_pn_gen.v
-f rtl/filelists/fmt_dds_bank.f
