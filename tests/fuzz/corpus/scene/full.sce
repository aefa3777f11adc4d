viewport position[0,0] resolution[640,480]
projection fov[45] nearclip[0.5] farclip[500]
eyespacing[0.065]
bgcolor[255,128,0]
background sky.png
skybox box.png
fog start[1] end[50] density[0.04] color[128,128,128] function[exp2]
mapmin[-10,-1,-10]
mapmax[10,5,10]
position[1,2,3]
rotation[0,90,0]
positionchange[10]
rotationchange[0.5]
light position[0,1,0,0] ambient[51,51,51] diffuse[255,255,255] specular[255,255,255]
diffuse[255,0,0]
shininess[20]
import tri.obj
emission[0,0,255]
importdir models
terrain hills.pgm amplitude[2] position[-1,0,-1]
