// fmt_dds_bank: the row tone generators (sine ROM shared by engines)
+incdir+rtl
rtl/fmt_dds_bank.v
rtl/fmt_dds_chan.v
rtl/fmt_dds_rom2.v
