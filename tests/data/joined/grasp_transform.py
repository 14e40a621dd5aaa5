# Forward kinematics of space_arm7 (numbers copied from urdf/space_arm7.urdf) at the capture
# instant of scenarios/robot_to_robot_capture.yaml, and the pose of spacedyn_twolink's hand (base
# at the scenario's position, identity orientation, q = 0: hand at base + (5, 0, 0)) in the
# end_effector frame: the grasp joint's origin.
import math
def mm(A,B): return [[sum(A[i][k]*B[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
def mv(A,v): return [sum(A[i][k]*v[k] for k in range(3)) for i in range(3)]
def T(A): return [[A[j][i] for j in range(3)] for i in range(3)]
def rx(a): c,s=math.cos(a),math.sin(a); return [[1,0,0],[0,c,-s],[0,s,c]]
def ry(a): c,s=math.cos(a),math.sin(a); return [[c,0,s],[0,1,0],[-s,0,c]]
def rz(a): c,s=math.cos(a),math.sin(a); return [[c,-s,0],[s,c,0],[0,0,1]]
def rpy(r,p,y): return mm(rz(y),mm(ry(p),rx(r)))
def rot(axis,q):
    return {'x':rx,'y':ry,'z':rz}[axis](q)
joints=[((0.05,0.02,0.8),(0,0,0),'z'),((0,0,0.25),(0,-1.57079633,-1.57079633),'z'),((0.2,0,0.12),(-1.57079633,0,0),'z'),
        ((1.3,0,0),(0,0,0),'z'),((1.25,0,0),(0,-1.57079633,-3.14159265),'x'),((0,-0.12,0.18),(0,0,0),'y'),((0,0,0.17),(0,0,0),'z')]
q=[0,0.7,0.9,0.8,0,-0.6,0]
R=[[1,0,0],[0,1,0],[0,0,1]]; p=[0,0,0]
for (xyz,r,ax),qi in zip(joints,q):
    p=[p[i]+mv(R,xyz)[i] for i in range(3)]
    R=mm(R,mm(rpy(*r),rot(ax,qi)))
p=[p[i]+mv(R,(0,0,0.15))[i] for i in range(3)]   # ee_joint
h=[p[i]+mv(R,(0,0,0.05))[i] for i in range(3)]   # contact point
print("contact point", ["%.17g"%x for x in h])
base=(-4.6810623747200945, -2.5837731448252454, 1.6935908031971343)
hand=[base[0]+5,base[1],base[2]]
print("hand", ["%.17g"%x for x in hand], "gap", math.dist(h,hand))
Rr=T(R)
pr=mv(Rr,[hand[i]-p[i] for i in range(3)])
pitch=math.asin(-Rr[2][0]); roll=math.atan2(Rr[2][1],Rr[2][2]); yaw=math.atan2(Rr[1][0],Rr[0][0])
print('origin xyz="%.17g %.17g %.17g" rpy="%.17g %.17g %.17g"'%(*pr,roll,pitch,yaw))
