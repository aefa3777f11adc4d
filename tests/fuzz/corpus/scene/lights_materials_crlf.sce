# a walk-through with two lights and materials
projection fov[60] nearclip[0.1] farclip[1000]
bgcolor[10,20,30]
light position[0,10,0,1] ambient[20,20,20] diffuse[200,200,180] specular[255,255,255]
light position[1,1,1,0] diffuse[50,50,90]
ambient[40,40,40]
diffuse[200,10,10]
specular[255,255,255]
shininess[64]
import a.obj
diffuse[10,200,10]
import b.obj
position[0,1.7,5]
rotation[-10,0,0]
