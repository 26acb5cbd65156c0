// fmt_uart_rx -- UART receiver, 8N1, oversampled at the full clock rate.
//
// The line is synchronised by two flip-flops.  A falling edge starts a byte; the start
// bit is validated at its middle (DIV/2 clocks later: still low, else the edge was a
// glitch and the receiver returns to idle).  Every bit (start, 8 data, stop) is decided
// by a majority vote of three samples on consecutive clocks centred on the middle of the
// bit, DIV clocks apart.  A low stop bit sets frame_err_o together with valid_o (the byte
// is delivered but marked) and the receiver waits for the line to return high before it
// looks for the next start bit (a break does not produce a stream of bytes).
// Latency: valid_o pulses for one cycle about DIV/2 + 4 clocks after the middle of the
// stop bit (two synchroniser stages, vote, output register).  DIV >= 4.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_uart_rx #(
    parameter DIV = 1085              // clocks per bit (>= 4), same as fmt_uart_tx
) (
    input  wire       clk,
    input  wire       rst,            // synchronous, active high
    input  wire       rxd_i,          // serial line (asynchronous), idle high
    output reg  [7:0] data_o,         // received byte, valid with valid_o
    output reg        valid_o,        // one-cycle pulse per received byte
    output reg        frame_err_o     // with valid_o: the stop bit was low
);

    localparam CW = $clog2(DIV + 1);

    localparam S_IDLE = 2'd0, S_BITS = 2'd1, S_WAIT_HIGH = 2'd2;

    reg [1:0]    sync_q;              // two-stage synchroniser
    reg [2:0]    hist_q;              // last three synchronised samples (vote window)
    reg [1:0]    state_q;
    reg [CW-1:0] cnt_q;               // clocks since the start edge / the last vote
    reg [3:0]    nbit_q;              // bits voted so far in this byte (0 = start)
    reg [7:0]    shift_q;

    wire [31:0]  cnt32 = {{(32-CW){1'b0}}, cnt_q};
    // the start bit is voted DIV/2 + 1 clocks after the edge, every other bit DIV later
    wire         at_vote = (nbit_q == 4'd0) ? (cnt32 == DIV / 2) : (cnt32 == DIV - 1);
    wire vote = (hist_q[0] & hist_q[1]) | (hist_q[0] & hist_q[2]) | (hist_q[1] & hist_q[2]);

    always @(posedge clk) begin
        if (rst) begin
            sync_q      <= 2'b11;
            hist_q      <= 3'b111;
            state_q     <= S_IDLE;
            cnt_q       <= {CW{1'b0}};
            nbit_q      <= 4'd0;
            shift_q     <= 8'h00;
            data_o      <= 8'h00;
            valid_o     <= 1'b0;
            frame_err_o <= 1'b0;
        end else begin
            sync_q  <= {sync_q[0], rxd_i};
            hist_q  <= {hist_q[1:0], sync_q[1]};
            valid_o <= 1'b0;
            case (state_q)
                S_IDLE: begin
                    // hist_q[0] is the newest sample: a high -> low edge starts a byte
                    if (hist_q[1] && !hist_q[0]) begin
                        state_q <= S_BITS;
                        nbit_q  <= 4'd0;
                        cnt_q   <= {CW{1'b0}};
                    end
                end
                S_BITS: begin
                    if (!at_vote) begin
                        cnt_q <= cnt_q + 1'b1;
                    end else begin
                        cnt_q  <= {CW{1'b0}};
                        nbit_q <= nbit_q + 1'b1;
                        if (nbit_q == 4'd0) begin
                            if (vote) state_q <= S_IDLE;          // glitch, not a start bit
                        end else if (nbit_q <= 4'd8) begin
                            shift_q <= {vote, shift_q[7:1]};      // LSB first
                        end else begin
                            data_o      <= shift_q;
                            valid_o     <= 1'b1;
                            frame_err_o <= ~vote;
                            state_q     <= vote ? S_IDLE : S_WAIT_HIGH;
                        end
                    end
                end
                S_WAIT_HIGH: begin
                    if (hist_q[0] && hist_q[1]) state_q <= S_IDLE;
                end
                default: state_q <= S_IDLE;
            endcase
        end
    end

endmodule
`default_nettype wire
