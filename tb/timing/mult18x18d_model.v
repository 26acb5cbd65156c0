// Behavioural model of the ECP5 MULT18X18D, only as far as tb/timing/test_ecp5_dsp_pack.py
// needs it (written here from the cell's parameter list in Yosys's cells_bb.v and the
// ECP5 sysDSP usage guide's description; NOT Lattice's model): an 18 x 18 product,
// signed per SIGNEDA / SIGNEDB, with optional input registers (A, B) and output register
// (P) on CLK0, each with the clock enable its parameter names (CE0..CE3) and a
// synchronous reset (RST0..RST3, RESETMODE "SYNC").  No pipeline register, no cascade.
`default_nettype none
module MULT18X18D #(
    parameter REG_INPUTA_CLK = "NONE", parameter REG_INPUTA_CE = "CE0", parameter REG_INPUTA_RST = "RST0",
    parameter REG_INPUTB_CLK = "NONE", parameter REG_INPUTB_CE = "CE0", parameter REG_INPUTB_RST = "RST0",
    parameter REG_INPUTC_CLK = "NONE", parameter REG_INPUTC_CE = "CE0", parameter REG_INPUTC_RST = "RST0",
    parameter REG_PIPELINE_CLK = "NONE", parameter REG_PIPELINE_CE = "CE0", parameter REG_PIPELINE_RST = "RST0",
    parameter REG_OUTPUT_CLK = "NONE", parameter REG_OUTPUT_CE = "CE0", parameter REG_OUTPUT_RST = "RST0",
    parameter CLK0_DIV = "ENABLED", parameter CLK1_DIV = "ENABLED", parameter CLK2_DIV = "ENABLED",
    parameter CLK3_DIV = "ENABLED", parameter HIGHSPEED_CLK = "NONE", parameter GSR = "ENABLED",
    parameter CAS_MATCH_REG = "FALSE", parameter SOURCEB_MODE = "B_SHIFT",
    parameter MULT_BYPASS = "DISABLED", parameter RESETMODE = "SYNC"
) (
    input wire A0, A1, A2, A3, A4, A5, A6, A7, A8, A9, A10, A11, A12, A13, A14, A15, A16, A17,
    input wire B0, B1, B2, B3, B4, B5, B6, B7, B8, B9, B10, B11, B12, B13, B14, B15, B16, B17,
    input wire C0, C1, C2, C3, C4, C5, C6, C7, C8, C9, C10, C11, C12, C13, C14, C15, C16, C17,
    input wire SIGNEDA, SIGNEDB, SOURCEA, SOURCEB,
    input wire CLK0, CLK1, CLK2, CLK3, CE0, CE1, CE2, CE3, RST0, RST1, RST2, RST3,
    output wire P0, P1, P2, P3, P4, P5, P6, P7, P8, P9, P10, P11, P12, P13, P14, P15, P16, P17,
    output wire P18, P19, P20, P21, P22, P23, P24, P25, P26, P27, P28, P29, P30, P31, P32, P33,
    output wire P34, P35
);
    wire [17:0] a = {A17, A16, A15, A14, A13, A12, A11, A10, A9, A8, A7, A6, A5, A4, A3, A2, A1, A0};
    wire [17:0] b = {B17, B16, B15, B14, B13, B12, B11, B10, B9, B8, B7, B6, B5, B4, B3, B2, B1, B0};
    function sel_ce;
        input [8*3-1:0] name;
        input c0, c1, c2, c3;
        sel_ce = (name == "CE0") ? c0 : (name == "CE1") ? c1 : (name == "CE2") ? c2 : c3;
    endfunction
    function sel_rst;
        input [8*4-1:0] name;
        input r0, r1, r2, r3;
        sel_rst = (name == "RST0") ? r0 : (name == "RST1") ? r1 : (name == "RST2") ? r2 : r3;
    endfunction
    wire cea = sel_ce(REG_INPUTA_CE, CE0, CE1, CE2, CE3);
    wire ceb = sel_ce(REG_INPUTB_CE, CE0, CE1, CE2, CE3);
    wire cep = sel_ce(REG_OUTPUT_CE, CE0, CE1, CE2, CE3);
    wire rsa = sel_rst(REG_INPUTA_RST, RST0, RST1, RST2, RST3);
    wire rsb = sel_rst(REG_INPUTB_RST, RST0, RST1, RST2, RST3);
    wire rsp = sel_rst(REG_OUTPUT_RST, RST0, RST1, RST2, RST3);
    reg [17:0] a_q = 18'd0, b_q = 18'd0;
    reg [35:0] p_q = 36'd0;
    always @(posedge CLK0) begin
        if (rsa) a_q <= 18'd0; else if (cea) a_q <= a;
        if (rsb) b_q <= 18'd0; else if (ceb) b_q <= b;
    end
    wire [17:0] a_u = (REG_INPUTA_CLK == "NONE") ? a : a_q;
    wire [17:0] b_u = (REG_INPUTB_CLK == "NONE") ? b : b_q;
    wire signed [36:0] a_x = SIGNEDA ? {{19{a_u[17]}}, a_u} : {19'd0, a_u};
    wire signed [36:0] b_x = SIGNEDB ? {{19{b_u[17]}}, b_u} : {19'd0, b_u};
    wire [36:0] prod = a_x * b_x;
    always @(posedge CLK0) begin
        if (rsp) p_q <= 36'd0; else if (cep) p_q <= prod[35:0];
    end
    wire [35:0] p = (REG_OUTPUT_CLK == "NONE") ? prod[35:0] : p_q;
    assign {P35, P34, P33, P32, P31, P30, P29, P28, P27, P26, P25, P24, P23, P22, P21, P20, P19, P18,
            P17, P16, P15, P14, P13, P12, P11, P10, P9, P8, P7, P6, P5, P4, P3, P2, P1, P0} = p;
endmodule
`default_nettype wire
