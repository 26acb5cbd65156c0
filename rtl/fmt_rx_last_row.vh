// fmt_rx_last_row.vh -- constant functions included INSIDE a receive module
// (fmt_rx_array, fmt_col_pair_rx), which must have LOG2_N, ROWS, BIN_LO and BIN_STEP in
// scope.  last_row_f(0) is the comb row that completes last in a window: rows come out
// of the pair split when the later of their two bins k and N - k leaves the FFT, in
// bit-reversed order (twin: sim/fmt/rx_array.py row_order).
function integer bitrev_f;
    input integer v;
    integer j;
    begin
        bitrev_f = 0;
        for (j = 0; j < LOG2_N; j = j + 1)
            if (((v >> j) & 1) != 0) bitrev_f = bitrev_f | (1 << (LOG2_N - 1 - j));
    end
endfunction
function integer last_row_f;
    input integer dummy;
    integer r, k, s, best;
    begin
        best = -1;
        last_row_f = 0;
        for (r = 0; r < ROWS; r = r + 1) begin
            k = BIN_LO + r * BIN_STEP;
            s = (bitrev_f(k) > bitrev_f((1 << LOG2_N) - k)) ? bitrev_f(k) : bitrev_f((1 << LOG2_N) - k);
            if (s > best) begin
                best = s;
                last_row_f = r + 0 * dummy;
            end
        end
    end
endfunction
