angle increment: 1e300
