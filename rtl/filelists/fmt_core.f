// fmt_core: the whole controller
+incdir+rtl
rtl/fmt_core.v
rtl/fmt_regfile.v
rtl/fmt_latency.v
-f rtl/filelists/fmt_tx.f
-f rtl/filelists/fmt_rx_array.f
-f rtl/filelists/fmt_touch.f
-f rtl/filelists/fmt_ctrl_port.f
rtl/fmt_report_fifo.v
