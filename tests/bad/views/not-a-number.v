angle increment: 20
initial line width: thick
