// COBS-encodes the engine's reply buffer (up to 63 bytes, so every block is shorter than
// 254 bytes) and hands the bytes, then one 0x00 delimiter, to a byte transmitter.
module cobs_tx (
    input  wire       clk,
    input  wire       rst,
    input  wire       start,         // pulse: a reply of len bytes is in the buffer
    input  wire [5:0] len,
    output reg  [5:0] idx,           // buffer read address
    input  wire [7:0] buf_byte,      // buffer[idx]
    output wire       busy,
    output reg        out_valid,
    output reg  [7:0] out_data,
    input  wire       out_ready
);
    localparam [2:0] S_IDLE = 0, S_SCAN = 1, S_CODE = 2, S_DATA = 3, S_DELIM = 4;
    reg [2:0] state;
    reg [5:0] n;        // reply length
    reg [5:0] blk;      // first byte of the current block
    reg [5:0] stop;     // index of the zero (or n) that ends the block

    assign busy = (state != S_IDLE);

    always @(posedge clk) begin
        if (rst) begin
            state <= S_IDLE;
            out_valid <= 1'b0;
        end else begin
            if (out_valid && out_ready) out_valid <= 1'b0;
            case (state)
            S_IDLE: if (start) begin
                n <= len;
                blk <= 0;
                idx <= 0;
                state <= S_SCAN;
            end
            S_SCAN:  // idx walks from blk to the next zero or the end of the reply
                if (idx == n || buf_byte == 8'h00) begin
                    stop <= idx;
                    state <= S_CODE;
                end else idx <= idx + 1'b1;
            S_CODE: if (!out_valid) begin
                out_valid <= 1'b1;
                out_data <= {2'b00, stop - blk} + 8'd1;
                idx <= blk;
                state <= S_DATA;
            end
            S_DATA: if (!out_valid) begin
                if (idx == stop) begin
                    if (stop == n) state <= S_DELIM;
                    else begin  // skip the zero; the next block starts after it
                        blk <= stop + 1'b1;
                        idx <= stop + 1'b1;
                        state <= S_SCAN;
                    end
                end else begin
                    out_valid <= 1'b1;
                    out_data <= buf_byte;
                    idx <= idx + 1'b1;
                end
            end
            S_DELIM: if (!out_valid) begin
                out_valid <= 1'b1;
                out_data <= 8'h00;
                state <= S_IDLE;
            end
            default: state <= S_IDLE;
            endcase
        end
    end
endmodule
