// fmt_uart_tb_top -- SIMULATION-ONLY test top (not part of rtl/): fmt_uart_tx and
// fmt_uart_rx; loop_i = 1 feeds the transmitter's line into the receiver, loop_i = 0
// lets the test drive the receiver's line (rxd_i) directly.
`default_nettype none

module fmt_uart_tb_top #(
    parameter DIV = 4                 // clocks per bit
) (
    input  wire       clk,
    input  wire       rst,
    input  wire       loop_i,         // 1: rx line = tx line
    input  wire [7:0] tx_data_i,
    input  wire       tx_valid_i,
    output wire       tx_ready_o,
    output wire       txd_o,
    input  wire       rxd_i,
    output wire [7:0] rx_data_o,
    output wire       rx_valid_o,
    output wire       rx_frame_err_o
);
    fmt_uart_tx #(.DIV(DIV)) u_tx (
        .clk(clk), .rst(rst), .data_i(tx_data_i), .valid_i(tx_valid_i),
        .ready_o(tx_ready_o), .txd_o(txd_o));
    fmt_uart_rx #(.DIV(DIV)) u_rx (
        .clk(clk), .rst(rst), .rxd_i(loop_i ? txd_o : rxd_i),
        .data_o(rx_data_o), .valid_o(rx_valid_o), .frame_err_o(rx_frame_err_o));
endmodule
`default_nettype wire
