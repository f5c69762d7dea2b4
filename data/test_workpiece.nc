%
(deflect's test workpiece after Haehn and Weigold 2020, sec. 3: grooves, a ramp, a circular pocket)
(our own drawing, the paper gives no dimensions: stock 140 x 130 mm, top at Z0, workpiece frame)
(tool: 16 mm three-flute flat end mill; 25 mm/s = F1500; 13000 rpm)
N10 G21 G90 G17 G40 G49 G80 G94
N20 G0 Z10
N30 S13000 M3
(groove 1: 5 mm deep along +x at Y20, in and out through the stock's ends)
N40 G0 X-15 Y20
N50 G1 Z-5 F1500
N60 X155
N70 G0 Z10
(groove 2: 8 mm deep along -x at Y50)
N80 G0 X155 Y50
N90 G1 Z-8 F1500
N100 X-15
N110 G0 Z10
(ramp: from 2 to 8 mm deep along +x at Y80, then level to the exit)
N120 G0 X-15 Y80
N130 G1 Z-2 F1500
N140 X0
N150 X100 Z-8
N160 X155
N170 G0 Z10
(circular pocket: helical entry to 6 mm in three turns of radius 8 about X70 Y110, a turn at depth)
N180 G0 X78 Y110
N190 G1 Z0 F1500
N200 G3 X78 Y110 Z-2 I-8 J0
N210 G3 X78 Y110 Z-4 I-8 J0
N220 G3 X78 Y110 Z-6 I-8 J0
N230 G3 X78 Y110 I-8 J0
N240 G1 X70 Y110
N250 G0 Z10
N260 M5
N270 M30
%
