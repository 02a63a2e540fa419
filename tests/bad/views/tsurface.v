angle increment: 20
tsurface: t leaf.ray 1
