# Writes sliver.msh: a 2 x 1 rectangle whose grid has one column (x in [1, 1.002])
# and one row (y in [0.5, 0.501]) of sliver triangles, aspect ratio about 100.
# Run in this directory: python3 sliver.py
import numpy as np
xs=np.r_[np.linspace(0,1,11), 1.002, np.linspace(1.102,2.002,10)]
ys=np.r_[np.linspace(0,0.5,6), 0.501, np.linspace(0.601,1.001,5)]
nx,ny=len(xs),len(ys)
P=[(x,y) for y in ys for x in xs]
idx=lambda i,j: j*nx+i+1
tris=[];lines=[]
for j in range(ny-1):
    for i in range(nx-1):
        a,b,c,d=idx(i,j),idx(i+1,j),idx(i+1,j+1),idx(i,j+1)
        tris += [(a,b,c),(a,c,d)]
for i in range(nx-1): lines.append((1,idx(i,0),idx(i+1,0)))        # floor
for j in range(ny-1): lines.append((2,idx(nx-1,j),idx(nx-1,j+1)))  # right
for i in range(nx-1): lines.append((3,idx(i+1,ny-1),idx(i,ny-1)))  # top
for j in range(ny-1): lines.append((4,idx(0,j+1),idx(0,j)))        # left
with open('sliver.msh','w') as f:
    f.write('$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n5\n1 1 "floor"\n1 2 "right"\n1 3 "top"\n1 4 "left"\n2 5 "domain"\n$EndPhysicalNames\n')
    f.write('$Nodes\n%d\n'%len(P))
    for k,(x,y) in enumerate(P): f.write('%d %.17g %.17g 0\n'%(k+1,x,y))
    f.write('$EndNodes\n$Elements\n%d\n'%(len(lines)+len(tris)))
    k=1
    for (t,a,b) in lines: f.write('%d 1 2 %d %d %d %d\n'%(k,t,t,a,b)); k+=1
    for (a,b,c) in tris: f.write('%d 2 2 5 5 %d %d %d\n'%(k,a,b,c)); k+=1
    f.write('$EndElements\n')
