// fmt_sorted_list -- a K-entry list kept sorted by insertion, one insert per cycle
// (shared by fmt_localmax: the candidate list, and fmt_blob: the blob list).
//
// Order: entry 0 first.  An entry is (key, tie, payload).  Keys rank descending, equal
// keys by tie ascending; an inserted entry goes ahead of entries equal to it in both
// (none occur in the two users: the tie is a raster index, unique per frame).  Entry i
// stays ahead of an inserted one when it is valid and {key, ~tie} > {ins_key, ~ins_tie}
// (one comparator per entry); the inserted one takes the first place not ahead of it,
// the entries behind move down one place and the last one leaves the list.  Invalid
// entries rank last and move like valid ones (with their key and payload).
//
// Operations (one cycle each, registered; entries read on the outputs):
//   ins_i    insert (ins_key_i, ins_tie_i, ins_pay_i).
//   pop_i    remove entry 0: entries 1..K-1 move up one place, entry K-1 becomes
//            invalid (it keeps its key and tie and takes entry 0's payload, so the
//            payloads stay a permutation).  Not in the same cycle as an insert (the
//            users never do both; simulation reports it).
//   clear_i  every entry invalid (keys and payloads kept).  Overrides the valid flags
//            of an insert or pop in the same cycle.
//   rst      every entry invalid; with PAY_RST_IDX = 1 also entry i's payload = i and
//            drop_pay_o = K (payloads and drop_pay_o then stay a permutation of 0..K:
//            fmt_blob uses them as slot numbers of a (K+1)-slot RAM, inserting with
//            ins_pay_i = drop_pay_o, the free slot).
// drop_pay_o: the payload that is out of the list after the latest insert: the old
// entry K-1 (valid or not) when the inserted entry ranks ahead of it, else the
// inserted payload itself.  Not changed by pop or clear.
//
// PAY_W = 0: no payload registers (pay_o and drop_pay_o are one constant 0 bit per
// entry; fmt_localmax sorts (z, raster index) only).
//
// HAS_POP = 0 removes the pop select (Yosys synth_xilinx keeps the module as a block,
// so a constant pop_i = 0 at the instance would not remove it): fmt_blob never pops.
//
// EARLY = 1: the comparisons are made a cycle early and registered: nxt_key_i and
// nxt_tie_i give the key and tie of the next cycle's insert (the user's register inputs
// of ins_key_i / ins_tie_i; they must equal them in every cycle with ins_i, simulation
// reports a mismatch).  Every entry is compared with them as it will be in the next
// cycle: the results (and the inserted entry's own, one more comparator) move with their
// entries on an insert or pop, so no comparator is between ins_key_i and the entries'
// enables.  EARLY = 0: ins_key_i is compared in the cycle of the insert (nxt_* unused).
// NXT_CP (EARLY = 1): nxt_key_i in NXT_CP equal copies (the user's registers): entry i
// compares with copy i * NXT_CP / K, the inserted entry with copy 0, so no one register
// drives all K comparators (simulation reports copies that differ).
// AHEAD_IN (EARLY = 1): 1 takes the inserted entry's own comparison from ins_ahead_i
// instead of the comparator: {ins_key_i, ~ins_tie_i} > {nxt_key_i, ~nxt_tie_i}, which the
// user registers a cycle early (from the keys of the insert after next), so the one
// result that goes to every entry's enable select leaves a flip-flop, not a carry chain
// (simulation reports an insert whose ins_ahead_i differs from the comparison).
//
// Cost: K comparators of KEY_W + TIE_W bits, a 3:1 (2:1 with HAS_POP = 0) select per
// entry bit; no arithmetic beyond the comparators.  Against the lists the two blocks
// had inline (Yosys synth_xilinx, scripts/synth.py): fmt_localmax 6,555 -> 6,507 LUT,
// fmt_blob 10,994 -> 10,982 LUT, flip-flops and cycle counts unchanged.
`default_nettype none

module fmt_sorted_list #(
    parameter K           = 8,   // entries (>= 1)
    parameter KEY_W       = 16,  // sort key width, unsigned, ranked descending (>= 1)
    parameter TIE_W       = 10,  // tie-break key width, unsigned, ranked ascending (>= 1)
    parameter PAY_W       = 4,   // payload width; 0 = no payload (pay_o, drop_pay_o are one
                                 // constant 0 bit per entry); >= $clog2(K + 1) with PAY_RST_IDX
    parameter PAY_RST_IDX = 0,   // 1: rst sets payload i = i and drop_pay_o = K; 0: no reset
    parameter HAS_POP     = 1,   // 1: pop_i works; 0: pop_i is ignored (no pop circuit)
    parameter EARLY       = 0,   // 1: compare with nxt_key_i / nxt_tie_i a cycle early
    parameter NXT_CP      = 1,   // EARLY = 1: copies of nxt_key_i (>= 1, <= K)
    parameter AHEAD_IN    = 0    // EARLY = 1: 1 = the inserted entry's comparison is
                                 // ins_ahead_i (registered by the user); 0 = compared here
) (
    input  wire               clk,
    input  wire               rst,         // synchronous, active high
    input  wire               clear_i,     // all entries invalid
    input  wire               ins_i,       // insert this cycle
    input  wire [KEY_W-1:0]   ins_key_i,   // its key (descending)
    input  wire [TIE_W-1:0]   ins_tie_i,   // its tie-break key (ascending)
    /* verilator lint_off UNUSEDSIGNAL */  // EARLY = 0: not read
    input  wire [NXT_CP*KEY_W-1:0] nxt_key_i,   // EARLY = 1: ins_key_i of the next cycle
                                           // (copy c at [c*KEY_W +: KEY_W])
    input  wire [TIE_W-1:0]   nxt_tie_i,   // EARLY = 1: ins_tie_i of the next cycle
    input  wire               ins_ahead_i, // AHEAD_IN = 1: the insert ranks ahead of the next
    /* verilator lint_on UNUSEDSIGNAL */
    input  wire [((PAY_W > 0) ? PAY_W : 1)-1:0]   ins_pay_i,   // its payload
    input  wire               pop_i,       // remove entry 0, the rest moves up (HAS_POP = 1)
    output reg  [K-1:0]       valid_o,     // entry i holds data
    output reg  [K*KEY_W-1:0] key_o,       // entry i at [i*KEY_W +: KEY_W]
    output reg  [K*TIE_W-1:0] tie_o,       // entry i at [i*TIE_W +: TIE_W]
    output wire [K*((PAY_W > 0) ? PAY_W : 1)-1:0] pay_o,       // entry i at [i*PAY_W +: PAY_W]
    output wire [((PAY_W > 0) ? PAY_W : 1)-1:0]   drop_pay_o   // out of the list after the last insert
);

    localparam IW = $clog2(K + 1);         // bits of an entry number 0..K

    // synthesis translate_off
    initial begin
        if (K < 1 || KEY_W < 1 || TIE_W < 1 || PAY_W < 0) begin
            $display("fmt_sorted_list: K %0d, KEY_W %0d, TIE_W %0d must be >= 1, PAY_W %0d >= 0",
                     K, KEY_W, TIE_W, PAY_W);
            $finish;
        end
        if (HAS_POP != 0 && HAS_POP != 1) begin
            $display("fmt_sorted_list: HAS_POP %0d must be 0 or 1", HAS_POP);
            $finish;
        end
        if (PAY_RST_IDX != 0 && PAY_RST_IDX != 1) begin
            $display("fmt_sorted_list: PAY_RST_IDX %0d must be 0 or 1", PAY_RST_IDX);
            $finish;
        end
        if (EARLY != 0 && EARLY != 1) begin
            $display("fmt_sorted_list: EARLY %0d must be 0 or 1", EARLY);
            $finish;
        end
        if (AHEAD_IN != 0 && (AHEAD_IN != 1 || EARLY != 1)) begin
            $display("fmt_sorted_list: AHEAD_IN %0d must be 0, or 1 with EARLY = 1 (EARLY %0d)",
                     AHEAD_IN, EARLY);
            $finish;
        end
        if (NXT_CP < 1 || NXT_CP > K) begin
            $display("fmt_sorted_list: NXT_CP %0d must be 1 .. K (%0d)", NXT_CP, K);
            $finish;
        end
        if (PAY_RST_IDX == 1 && PAY_W < IW) begin
            $display("fmt_sorted_list: PAY_W %0d < %0d bits of the entry numbers 0..K (K %0d)",
                     PAY_W, IW, K);
            $finish;
        end
    end
    always @(posedge clk) begin
        if (!rst && ins_i && pop_i && HAS_POP == 1)
            $display("%m: ERROR: insert and pop in the same cycle at %0t", $time);
    end
    // synthesis translate_on

    // entry i stays ahead of the inserted entry
    reg [K-1:0] better;
    generate
        if (EARLY == 1) begin : g_early
            // ahead_q[i]: entry i (as it is now) ranks ahead of this cycle's insert
            reg [K-1:0] ahead_q;
            reg [K-1:0] ahead_c;               // entry i now ahead of the next insert
            wire        ahead_cmp = ({ins_key_i, ~ins_tie_i} > {nxt_key_i[0 +: KEY_W], ~nxt_tie_i});
            wire        ahead_ins = (AHEAD_IN == 1) ? ins_ahead_i : ahead_cmp;
            always @(*) begin : c_better
                integer i;
                for (i = 0; i < K; i = i + 1) begin
                    better[i]  = valid_o[i] && ahead_q[i];
                    ahead_c[i] = ({key_o[i*KEY_W +: KEY_W], ~tie_o[i*TIE_W +: TIE_W]} >
                                  {nxt_key_i[((i * NXT_CP) / K)*KEY_W +: KEY_W], ~nxt_tie_i});
                end
            end
            // the results move with their entries (as the list below)
            always @(posedge clk) begin : s_ahead
                integer i;
                ahead_q <= ahead_c;
                if (ins_i) begin
                    for (i = 0; i < K; i = i + 1)
                        if (!better[i])
                            ahead_q[i] <= (i == 0 || better[(i == 0) ? 0 : i - 1])
                                        ? ahead_ins : ahead_c[(i == 0) ? 0 : i - 1];
                end
                if (HAS_POP == 1 && pop_i) begin
                    for (i = 0; i < K - 1; i = i + 1)
                        ahead_q[i] <= ahead_c[i + 1];
                end
            end
            // synthesis translate_off
            reg [NXT_CP*KEY_W-1:0] nk_q;
            reg [TIE_W-1:0] nt_q;
            always @(posedge clk) begin
                nk_q <= nxt_key_i;
                nt_q <= nxt_tie_i;
                if (!rst && ins_i && (nk_q !== {NXT_CP{ins_key_i}} || nt_q !== ins_tie_i))
                    $display("%m: ERROR: insert differs from the previous nxt_key_i / nxt_tie_i at %0t",
                             $time);
                if (!rst && ins_i && AHEAD_IN == 1 && ins_ahead_i !== ahead_cmp)
                    $display("%m: ERROR: ins_ahead_i %b differs from the comparison at %0t",
                             ins_ahead_i, $time);
            end
            // synthesis translate_on
        end else begin : g_now
            always @(*) begin : c_better
                integer i;
                for (i = 0; i < K; i = i + 1)
                    better[i] = valid_o[i] && ({key_o[i*KEY_W +: KEY_W], ~tie_o[i*TIE_W +: TIE_W]} >
                                               {ins_key_i, ~ins_tie_i});
            end
        end
    endgenerate

    // ---- payloads: registers of PW bits (PAY_W = 0: 1 bit, unused, removed) -------------
    localparam PW = (PAY_W > 0) ? PAY_W : 1;
    /* verilator lint_off UNUSEDSIGNAL */     // PAY_W = 0: not read
    reg [K*PW-1:0] pay_q;
    reg [PW-1:0]   drop_q;
    /* verilator lint_on UNUSEDSIGNAL */
    // reset values (PAY_RST_IDX = 1): entry i holds i, the dropped payload K
    wire [(K+1)*PW-1:0] rst_pay;
    genvar gi;
    generate
        if (PAY_RST_IDX == 1) begin : g_rst
            for (gi = 0; gi <= K; gi = gi + 1) begin : g_e
                localparam [PW-1:0] IDX = gi;
                assign rst_pay[gi*PW +: PW] = IDX;
            end
        end else begin : g_nrst
            assign rst_pay = {((K+1)*PW){1'b0}};   // not used
        end
        if (PAY_W > 0) begin : g_pay
            assign pay_o      = pay_q;
            assign drop_pay_o = drop_q;
        end else begin : g_npay
            assign pay_o      = {K{1'b0}};
            assign drop_pay_o = 1'b0;
        end
    endgenerate

    // ---- the list ---------------------------------------------------------------------------
    always @(posedge clk) begin : s_list
        integer i;
        if (rst) begin
            valid_o <= {K{1'b0}};
            if (PAY_RST_IDX == 1) begin
                pay_q  <= rst_pay[K*PW-1:0];
                drop_q <= rst_pay[K*PW +: PW];
            end
        end else begin
            if (ins_i) begin
                // entry i takes the inserted entry when the one before stays ahead,
                // else entry i - 1
                for (i = 0; i < K; i = i + 1) begin
                    if (!better[i]) begin
                        if (i == 0 || better[(i == 0) ? 0 : i - 1]) begin
                            valid_o[i]              <= 1'b1;
                            key_o[i*KEY_W +: KEY_W] <= ins_key_i;
                            tie_o[i*TIE_W +: TIE_W] <= ins_tie_i;
                            pay_q[i*PW +: PW]       <= ins_pay_i;
                        end else begin
                            valid_o[i]              <= valid_o[(i == 0) ? 0 : i - 1];
                            key_o[i*KEY_W +: KEY_W] <= key_o[((i == 0) ? 0 : i - 1)*KEY_W +: KEY_W];
                            tie_o[i*TIE_W +: TIE_W] <= tie_o[((i == 0) ? 0 : i - 1)*TIE_W +: TIE_W];
                            pay_q[i*PW +: PW]       <= pay_q[((i == 0) ? 0 : i - 1)*PW +: PW];
                        end
                    end
                end
                // the old last entry leaves when the new one ranks ahead of it
                drop_q <= better[K-1] ? ins_pay_i : pay_q[(K-1)*PW +: PW];
            end
            if (HAS_POP == 1 && pop_i) begin
                for (i = 0; i < K - 1; i = i + 1) begin
                    valid_o[i]              <= valid_o[i + 1];
                    key_o[i*KEY_W +: KEY_W] <= key_o[(i + 1)*KEY_W +: KEY_W];
                    tie_o[i*TIE_W +: TIE_W] <= tie_o[(i + 1)*TIE_W +: TIE_W];
                    pay_q[i*PW +: PW]       <= pay_q[(i + 1)*PW +: PW];
                end
                valid_o[K-1]          <= 1'b0;
                pay_q[(K-1)*PW +: PW] <= pay_q[0 +: PW];
            end
            if (clear_i) valid_o <= {K{1'b0}};
        end
    end

endmodule

`default_nettype wire
