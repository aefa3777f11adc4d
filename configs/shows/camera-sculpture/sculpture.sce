# Basalt example: a live camera projected onto a sculpture (scene file, thesis appendix C.3).
bgcolor[0,0,0]
projection fov[35] nearclip[0.1] farclip[50]
position[0,0,4]
light position[0,0,10,0] ambient[90,90,90] diffuse[230,230,230] specular[40,40,40]
ambient[255,255,255]
diffuse[255,255,255]
shininess[4]
import sculpture.obj
