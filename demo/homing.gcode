; Homing on the simulated plotter: turn homing on, go somewhere, home, draw at machine zero.
$22=1
G0 X120 Y-60
G4 P0
$H
G0 X0 Y0
G2 X0 Y0 I20 J0 F2000
