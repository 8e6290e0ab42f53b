// RMII transmitter for replies: preamble, SFD, Ethernet header (to dst_mac, from
// SOURCE_MAC, EtherType), the reply buffer zero-padded to the 46-byte minimum payload, the
// FCS (complemented CRC-32, least significant byte first), then a 12-byte inter-frame gap.
module rmii_tx #(
    parameter [47:0] SOURCE_MAC = 48'h02695A065491,
    parameter [15:0] ETHERTYPE = 16'h88B5
) (
    input  wire        clk,
    input  wire        rst,
    input  wire        start,
    input  wire [5:0]  len,
    input  wire [47:0] dst_mac,
    output wire [5:0]  idx,
    input  wire [7:0]  buf_byte,
    output wire        busy,
    output reg         tx_en,
    output reg  [1:0]  txd
);
`include "crc32.vh"

    reg        active;
    reg [6:0]  pos;        // byte position: 0-7 preamble/SFD, 8.. frame, then FCS and gap
    reg [1:0]  dibit;
    reg [7:0]  cur;
    reg [31:0] crc;
    reg [5:0]  n;
    reg [47:0] dst;
    wire [6:0] fcs_at = 7'd8 + 7'd14 + ((n < 46) ? 7'd46 : {1'b0, n});  // first FCS byte
    assign idx = pos[5:0] - 6'd22;  // reply byte at frame position pos (mod 64)
    assign busy = active;

    // the byte at frame position pos: header, reply, padding, then the FCS
    reg [7:0] next_byte;
    always @* begin
        if (pos >= fcs_at) next_byte = ~crc[8 * (pos - fcs_at) +: 8];
        else if (pos < 7) next_byte = 8'h55;
        else if (pos == 7) next_byte = 8'hD5;
        else if (pos < 14) next_byte = dst[8 * (13 - pos) +: 8];
        else if (pos < 20) next_byte = SOURCE_MAC[8 * (19 - pos) +: 8];
        else if (pos == 20) next_byte = ETHERTYPE[15:8];
        else if (pos == 21) next_byte = ETHERTYPE[7:0];
        else if (pos - 7'd22 < {1'b0, n}) next_byte = buf_byte;
        else next_byte = 8'h00;
    end

    always @(posedge clk) begin
        if (rst) begin
            active <= 1'b0;
            tx_en <= 1'b0;
            txd <= 2'b00;
        end else if (!active) begin
            tx_en <= 1'b0;
            txd <= 2'b00;
            if (start) begin
                active <= 1'b1;
                n <= len;
                dst <= dst_mac;
                pos <= 0;
                dibit <= 0;
                crc <= 32'hFFFFFFFF;
            end
        end else begin
            if (dibit == 0) begin  // load the next byte
                cur <= next_byte;
                if (pos >= 8 && pos < fcs_at) crc <= crc32_byte(crc, next_byte);
                tx_en <= (pos < fcs_at + 4);
                txd <= (pos < fcs_at + 4) ? next_byte[1:0] : 2'b00;
            end else begin
                tx_en <= (pos < fcs_at + 4);
                txd <= (pos < fcs_at + 4) ? cur[2 * dibit +: 2] : 2'b00;
            end
            dibit <= dibit + 1'b1;
            if (dibit == 3) begin
                pos <= pos + 1'b1;
                if (pos == fcs_at + 4 + 12 - 1) active <= 1'b0;
            end
        end
    end
endmodule
