// fmt_uart_tx -- UART transmitter, 8 data bits LSB first, no parity, 1 stop bit (8N1).
//
// A byte is accepted at a clock edge where valid_i and ready_o are both high.  ready_o
// (combinational from the state) is high when idle and in the last clock of a stop bit,
// so a byte offered then starts its start bit right after the stop bit (no idle clock).  Each bit lasts DIV clocks (baud = clk / DIV;
// 125 MHz / 1085 = 115207 baud, +0.006 %).  The line (txd_o, registered) idles high.
// Latency: the start bit begins on the cycle after acceptance.  A byte takes 10 * DIV
// clocks; back-to-back bytes follow without an idle bit when valid_i is held.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_uart_tx #(
    parameter DIV = 1085              // clocks per bit (>= 2)
) (
    input  wire       clk,
    input  wire       rst,            // synchronous, active high
    input  wire [7:0] data_i,         // byte to send
    input  wire       valid_i,        // byte offered
    output wire       ready_o,        // 1 = idle, the byte is taken this cycle
    output reg        txd_o           // serial line, idle high
);

    localparam CW = $clog2(DIV + 1);

    reg [CW-1:0] cnt_q;               // clocks elapsed in the current bit
    reg [3:0]    bit_q;               // bits left to send (start + 8 data + stop = 10)
    reg [7:0]    shift_q;             // data bits still to send, LSB first (1s shifted in = stop)
    reg          busy_q;

    wire [31:0]  cnt32   = {{(32-CW){1'b0}}, cnt_q};
    wire         bit_end = (cnt32 == DIV - 1);

    wire         last_clk = busy_q && bit_end && (bit_q == 4'd1);   // last clock of the stop bit

    assign ready_o = ~busy_q | last_clk;

    always @(posedge clk) begin
        if (rst) begin
            cnt_q   <= {CW{1'b0}};
            bit_q   <= 4'd0;
            shift_q <= 8'hFF;
            busy_q  <= 1'b0;
            txd_o   <= 1'b1;
        end else if (!busy_q) begin
            txd_o <= 1'b1;
            if (valid_i) begin
                busy_q  <= 1'b1;
                shift_q <= data_i;
                bit_q   <= 4'd10;
                cnt_q   <= {CW{1'b0}};
                txd_o   <= 1'b0;              // start bit
            end
        end else begin
            if (!bit_end) begin
                cnt_q <= cnt_q + 1'b1;
            end else begin
                cnt_q   <= {CW{1'b0}};
                bit_q   <= bit_q - 1'b1;
                shift_q <= {1'b1, shift_q[7:1]};
                txd_o   <= shift_q[0];          // next bit; 1 (stop) after the data
                if (bit_q == 4'd1) begin          // stop bit done
                    if (valid_i) begin            // next byte right away
                        shift_q <= data_i;
                        bit_q   <= 4'd10;
                        txd_o   <= 1'b0;
                    end else begin
                        busy_q <= 1'b0;
                        txd_o  <= 1'b1;
                    end
                end
            end
        end
    end

endmodule
`default_nettype wire
