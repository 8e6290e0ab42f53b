// CRC-32 (IEEE 802.3 / zlib), reflected polynomial 0xEDB88320, register not inverted:
// callers start from 32'hFFFFFFFF and complement the result (or compare a residue).
function [31:0] crc32_byte;
    input [31:0] crc;
    input [7:0] data;
    integer b;
    reg [31:0] c;
    begin
        c = crc ^ {24'd0, data};
        for (b = 0; b < 8; b = b + 1)
            c = c[0] ? ((c >> 1) ^ 32'hEDB88320) : (c >> 1);
        crc32_byte = c;
    end
endfunction

// Four bytes of a word, most significant byte first (the protocol's big-endian order).
function [31:0] crc32_word;
    input [31:0] crc;
    input [31:0] word;
    begin
        crc32_word = crc32_byte(crc32_byte(crc32_byte(crc32_byte(crc, word[31:24]),
                                                      word[23:16]), word[15:8]), word[7:0]);
    end
endfunction
