// fmt_spi_wr -- write-only SPI master, LANES data lines sharing one SCLK and one
// active-low select (one word per line per transfer, MSB first).
//
// Timing (both board devices: the ADS5272-class ADC's serial control port and the
// AD9834-class DDS, which latch SDATA on the falling SCLK edge; as recalled from their
// data sheets, check before a board run): SCLK idles high; cs_n_o falls with the first
// bit on sdata_o; each bit is held DIV clk with SCLK high, then DIV clk with SCLK low
// (the device samples at the falling edge); after the last bit SCLK returns high and
// cs_n_o rises DIV clk later; busy_o falls DIV clk after that (the select's high time).
// A transfer takes (2 * WORD_W + 3) * DIV clk.  start_i is taken only when !busy_o.
// Storage: LANES x WORD_W shift register.  No model twin (tested against the device
// models in tb/fpga_xc5v).
`default_nettype none

module fmt_spi_wr #(
    parameter WORD_W = 16,   // bits per word
    parameter LANES  = 1,    // data lines (one word each per transfer)
    parameter DIV    = 4     // clk cycles per SCLK half period (>= 1)
) (
    input  wire                      clk,
    input  wire                      rst,       // synchronous, active high
    input  wire                      start_i,   // begin a transfer (ignored while busy_o)
    input  wire [LANES*WORD_W-1:0]   data_i,    // line l's word at [l*WORD_W +: WORD_W]
    output wire                      busy_o,    // a transfer is under way
    output wire                      sclk_o,    // serial clock, idle high
    output wire [LANES-1:0]          sdata_o,   // serial data, MSB first
    output wire                      cs_n_o     // select / FSYNC, active low
);
    localparam DIV_W = (DIV > 1) ? $clog2(DIV) : 1;
    localparam BIT_W = $clog2(WORD_W + 1);
    localparam [DIV_W-1:0] DIV_LAST = DIV[DIV_W-1:0] - 1'b1;
    localparam [BIT_W-1:0] BIT_LAST = WORD_W[BIT_W-1:0] - 1'b1;

    reg  [LANES*WORD_W-1:0] sh_q;
    reg  [DIV_W-1:0]        div_q;
    reg  [BIT_W-1:0]        bit_q;
    reg  [1:0]              ph_q;      // 0 SCLK high, 1 SCLK low, 2 after last bit, 3 select high
    reg                     busy_q, sclk_q, cs_n_q;
    wire                    tick = (div_q == DIV_LAST);

    integer l;
    always @(posedge clk) begin
        if (rst) begin
            busy_q <= 1'b0;
            sclk_q <= 1'b1;
            cs_n_q <= 1'b1;
            div_q  <= {DIV_W{1'b0}};
            bit_q  <= {BIT_W{1'b0}};
            ph_q   <= 2'd0;
            sh_q   <= {(LANES*WORD_W){1'b0}};
        end else if (!busy_q) begin
            if (start_i) begin
                busy_q <= 1'b1;
                cs_n_q <= 1'b0;
                sh_q   <= data_i;
                div_q  <= {DIV_W{1'b0}};
                bit_q  <= {BIT_W{1'b0}};
                ph_q   <= 2'd0;
            end
        end else begin
            div_q <= tick ? {DIV_W{1'b0}} : div_q + 1'b1;
            if (tick) begin
                case (ph_q)
                    2'd0: begin sclk_q <= 1'b0; ph_q <= 2'd1; end
                    2'd1: begin
                        sclk_q <= 1'b1;
                        if (bit_q == BIT_LAST) begin
                            ph_q <= 2'd2;
                        end else begin
                            ph_q  <= 2'd0;
                            bit_q <= bit_q + 1'b1;
                            for (l = 0; l < LANES; l = l + 1)
                                sh_q[l*WORD_W +: WORD_W] <= {sh_q[l*WORD_W +: WORD_W-1], 1'b0};
                        end
                    end
                    2'd2: begin cs_n_q <= 1'b1; ph_q <= 2'd3; end
                    default: busy_q <= 1'b0;
                endcase
            end
        end
    end

    genvar g;
    generate
        for (g = 0; g < LANES; g = g + 1) begin : g_sd
            assign sdata_o[g] = sh_q[g*WORD_W + WORD_W - 1];
        end
    endgenerate
    assign busy_o = busy_q;
    assign sclk_o = sclk_q;
    assign cs_n_o = cs_n_q;
endmodule
`default_nettype wire
