bgcolor 0 0 255
bgcolor [0.5, 1, 0]
fog start[1] colour[300,0,0] thickness[2]
light position[1,2,3]
bgcolor[1,2
