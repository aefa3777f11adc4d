# Basalt example: a video wall (scene file, thesis appendix C.3).
bgcolor[8,8,12]
projection fov[40] nearclip[0.1] farclip[100]
position[0,0,7]
rotation[0,0,0]
light position[0,2,10,0] ambient[60,60,60] diffuse[255,255,255] specular[80,80,80]
emission[0,0,0]
ambient[255,255,255]
diffuse[255,255,255]
shininess[8]
import wall.obj
