// fmt_crc16 -- one byte step of CRC-16/CCITT-FALSE (poly x^16 + x^12 + x^5 + 1 = 0x1021,
// MSB first, no reflection; the user starts from 0xFFFF and applies no final XOR).
//
// Purely combinational (no clock, no state): crc_o is the CRC after shifting the eight
// bits of data_i (bit 7 first) into crc_i.  The check value of "123456789" is 0x29B1
// (sim/fmt/protocol.py crc16 is the twin).  Depth: eight unrolled LFSR steps, which
// synthesis flattens to one XOR tree of at most ~10 inputs per bit.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_crc16 (
    input  wire [15:0] crc_i,         // CRC before this byte
    input  wire [7:0]  data_i,        // the byte, MSB first
    output reg  [15:0] crc_o          // CRC after this byte
);

    integer i;
    reg fb;

    always @(*) begin
        crc_o = crc_i;
        fb    = 1'b0;
        for (i = 7; i >= 0; i = i - 1) begin
            fb    = crc_o[15] ^ data_i[i];
            crc_o = {crc_o[14:0], 1'b0} ^ (fb ? 16'h1021 : 16'h0000);
        end
    end

endmodule
`default_nettype wire
