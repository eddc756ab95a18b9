; servoplot demo, as a GRBL sender would stream it
G21 G90
$$
G1 X0 Y0 F3000
; a square
G1 X40 Y0
G1 X40 Y40
G1 X0 Y40
G1 X0 Y0
; a five-pointed star inside it
G0 X20 Y38
G1 X31.76 Y3.82
G1 X1.98 Y25.85
G1 X38.02 Y25.85
G1 X8.24 Y3.82
G1 X20 Y38
?
G0 X0 Y0
