// fmt_despread -- column despreader ("unstir"): ADC sample times the receive PN sign.
//
// y = sign ? -x : x, computed in ADC_BITS + 1 bits so that -(-2^(ADC_BITS-1)) =
// +2^(ADC_BITS-1) is exact (no saturation exists or is needed).  Formats: x is
// ADC_BITS two's complement, y is ADC_BITS + 1 two's complement, same LSB.
// Timing: one register, advancing only when ce = 1 (latency 1 sample); reset clears y.
// Twin: sim/fmt/dds_bank.py despread_fixed.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_despread #(
    parameter ADC_BITS = `FMT_ADC_BITS      // ADC word width (two's complement)
) (
    input  wire                       clk,
    input  wire                       rst,      // synchronous, active high
    input  wire                       ce,       // sample strobe
    input  wire signed [ADC_BITS-1:0] adc_i,    // ADC sample
    input  wire                       sign_i,   // receive PN sign, 1 = multiply by -1
    output reg  signed [ADC_BITS:0]   y_o       // despread sample, registered
);

    wire signed [ADC_BITS:0] x_ext = {adc_i[ADC_BITS-1], adc_i};

    always @(posedge clk) begin
        if (rst) begin
            y_o <= {(ADC_BITS + 1){1'b0}};
        end else if (ce) begin
            y_o <= sign_i ? -x_ext : x_ext;
        end
    end

endmodule

`default_nettype wire
