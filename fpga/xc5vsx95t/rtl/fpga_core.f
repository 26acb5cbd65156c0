// fpga_core (XC5VSX95T board core, portable): fmt_core's list and the board's blocks
-f rtl/filelists/fmt_core.f
rtl/fmt_pn_gen.v
fpga/common/rtl/fmt_spi_wr.v
fpga/common/rtl/fmt_adc_deser.v
fpga/common/rtl/fmt_dds_prog.v
fpga/xc5vsx95t/rtl/fpga_core.v
