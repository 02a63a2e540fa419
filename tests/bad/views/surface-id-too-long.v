angle increment: 20
surface: leaf leaf.s 1
