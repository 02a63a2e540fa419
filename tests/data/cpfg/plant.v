angle increment: 45
initial line width: 0.2
surface: l leaf.s 1.5
viewpoint: 0,0,1
