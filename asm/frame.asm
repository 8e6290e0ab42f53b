// F-type instructions (func in bits 10:9, everything else zero), case, spacing, comments.
nr                                   ; => 0x00000200
nf                                   ; => 0x00000400
lr                                   ; => 0x00000600
er                                   ; => 0x00000000
NR                                   ; => 0x00000200
  Nf   // a comment                  ; => 0x00000400
	lr	; tabs and a ';' comment     ; => 0x00000600

// blank lines and comment-only lines emit nothing
   ; comment after spaces
nr 1                                 ; error: 'nr' takes no operands
er er                                ; error: 'er' takes no operands
er                                   ; => 0x00000000
er                                   ; => 0x00000000
