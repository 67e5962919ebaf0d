; A program in the style of hobby and Fanuc-like posts: semicolon comments, lower case,
; block delete, no spaces, decimal points missing.
g21g90g17
g0x0y0z50a0c0
/m8
g1z10f500
x10y10 ; a feed move
g2x20y0r10
g3x10y-10i0j-10
g0z50
m30
