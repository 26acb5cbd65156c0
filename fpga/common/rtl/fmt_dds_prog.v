// fmt_dds_prog -- programs ROWS AD9834-class DDS chips (one per row) with the tone plan
// and drives their bi-phase PN input.
//
// Bus: one SCLK and one FSYNC shared by all chips, one SDATA line per chip (fmt_spi_wr,
// 16-bit words, SCLK idle high, the chips latch on the falling edge): all chips are
// written at once.  Sequence after rst or start_i (every chip its own frequency word):
//   0x2100  control: B28 = 1, RESET bit = 1, PIN/SW = 0 (software reset while loading)
//   0x4000 | FREQ0[13:0], 0x4000 | FREQ0[27:14]    (B28: two consecutive 14-bit halves)
//   0xC000 | 0x000        PHASE0 = 0
//   0xE000 | 0x800        PHASE1 = 2048 / 4096 = 180 degrees
//   0x2200  control: B28 = 1, PIN/SW = 1 (FSELECT, PSELECT, RESET from the pins)
// then dds_reset_o (the chips' shared RESET pin, high while programming) falls on a ce
// cycle: every chip starts its phase at 0 on the same MCLK edge.  fsel_o stays 0 (FREQ0).
// Tone plan: with MCLK = fs * 2^MCLK_LOG2 (MCLK derived from the ADC's sample clock),
// row r's word is FREQ0 = (BIN_LO + r * BIN_STEP) << (28 - LOG2_N - MCLK_LOG2), so
// f = FREQ0 * MCLK / 2^28 = bin * fs / N exactly on the comb (sim/fmt/board.py
// dds_freq_words is the twin).  The chips' amplitude is set by their FS ADJUST resistor.
// PN: psel_o = pn_sign_i registered on ce (1 selects PHASE1 = the inverted tone).  The
// chip's pipeline from PSELECT to its DAC output (7 to 8 MCLK cycles in the AD9834 data
// sheet as recalled: verify) adds to the receive PN delay (fpga/xc5vsx95t/README.md).
// Storage: ROWS x 16-bit shift registers (fmt_spi_wr).  No model twin beyond the words.
`default_nettype none

module fmt_dds_prog #(
    parameter ROWS      = 4,    // rows = DDS chips
    parameter LOG2_N    = 6,    // FFT size N = 2^LOG2_N
    parameter BIN_LO    = 9,    // FFT bin of row 0
    parameter BIN_STEP  = 1,    // bins between rows
    parameter MCLK_LOG2 = 0,    // MCLK = fs * 2^MCLK_LOG2 (0: MCLK = fs)
    parameter SPI_DIV   = 4     // clk per SCLK half period (125 MHz: 15.6 MHz SCLK)
) (
    input  wire            clk,
    input  wire            rst,          // synchronous, active high
    input  wire            ce,           // sample strobe (fmt_core ce_o)
    input  wire            start_i,      // program again
    input  wire            pn_sign_i,    // PN transmit sign of the next sample (1 = -1)
    output wire            sclk_o,       // shared serial clock
    output wire [ROWS-1:0] sdata_o,      // serial data of row r's chip
    output wire            fsync_n_o,    // shared FSYNC
    output wire            psel_o,       // shared PSELECT pin (0 PHASE0, 1 PHASE1)
    output wire            fsel_o,       // shared FSELECT pin (0: FREQ0)
    output wire            dds_reset_o,  // shared RESET pin (high: outputs at mid-scale)
    output wire            done_o        // programmed, tones running
);
    localparam SHIFT = 28 - LOG2_N - MCLK_LOG2;     // frequency word = bin << SHIFT
    localparam [2:0] LAST = 3'd5;

    reg  [2:0]  step_q;       // word being sent
    reg         run_q, start_q, reset_q, done_q, psel_q;
    wire        busy;
    reg  [ROWS*16-1:0] words;
    integer r;
    reg  [31:0] fw;       // bits 31:28 are 0 for any valid plan
    /* verilator lint_off UNUSEDSIGNAL */  // fw[31:28]: above the chip's 28-bit word
    wire unused_fw = &{1'b0, fw[31:28]};
    /* verilator lint_on UNUSEDSIGNAL */
    always @(*) begin
        words = {(ROWS*16){1'b0}};
        fw    = 32'd0;
        for (r = 0; r < ROWS; r = r + 1) begin
            fw = (BIN_LO + r * BIN_STEP) << SHIFT;
            case (step_q)
                3'd0:    words[r*16 +: 16] = 16'h2100;
                3'd1:    words[r*16 +: 16] = {2'b01, fw[13:0]};
                3'd2:    words[r*16 +: 16] = {2'b01, fw[27:14]};
                3'd3:    words[r*16 +: 16] = 16'hC000;
                3'd4:    words[r*16 +: 16] = 16'hE800;
                default: words[r*16 +: 16] = 16'h2200;
            endcase
        end
    end

    always @(posedge clk) begin
        start_q <= 1'b0;
        if (rst || start_i) begin
            step_q  <= 3'd0;
            run_q   <= 1'b1;
            reset_q <= 1'b1;
            done_q  <= 1'b0;
            start_q <= 1'b0;
        end else if (run_q) begin
            if (!busy && !start_q) begin
                if (step_q == LAST + 1'b1) begin
                    if (ce) begin                 // release RESET on a sample edge
                        reset_q <= 1'b0;
                        done_q  <= 1'b1;
                        run_q   <= 1'b0;
                    end
                end else begin
                    start_q <= 1'b1;              // send words[step_q]
                end
            end
            if (start_q) step_q <= step_q + 1'b1;
        end
        if (rst)     psel_q <= 1'b0;
        else if (ce) psel_q <= pn_sign_i;
    end

    fmt_spi_wr #(.WORD_W(16), .LANES(ROWS), .DIV(SPI_DIV)) u_spi (
        .clk(clk), .rst(rst), .start_i(start_q), .data_i(words), .busy_o(busy),
        .sclk_o(sclk_o), .sdata_o(sdata_o), .cs_n_o(fsync_n_o));

    assign psel_o      = psel_q;
    assign fsel_o      = 1'b0;
    assign dds_reset_o = reset_q;
    assign done_o      = done_q;
endmodule
`default_nettype wire
