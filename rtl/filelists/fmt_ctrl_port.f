// fmt_ctrl_port: UART control port
+incdir+rtl
rtl/fmt_ctrl_port.v
rtl/fmt_uart_rx.v
rtl/fmt_uart_tx.v
rtl/fmt_crc16.v
