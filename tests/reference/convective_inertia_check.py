# Independent check of the convective film inertia (src/film/inertia.rs, eq. I1) at the seed
# bearing's 9,000 rpm equilibrium: trapezoid quadrature + central differences. python3 this.py
import numpy as np
rho,mu,R,L,c=900.,0.8e-3,0.03,0.03,40e-6
w=9000*2*np.pi/60
X,Y=0.000012805425082239526/c,0.00001703756289405643/c
t1,t2=np.radians(215.77863553381786),np.radians(68.2021535739826)+2*np.pi
th=np.linspace(t1,t2,4001)
def trap(f): return np.trapezoid(f,th)
def Fin(q,qd,parts):
    x,y=q; xd,yd=qd
    h=1-x*np.cos(th)-y*np.sin(th)   # /c
    hth=x*np.sin(th)-y*np.cos(th)
    htt=x*np.cos(th)+y*np.sin(th)
    hd=-(xd*np.cos(th)+yd*np.sin(th))  # /c per s
    hdth=xd*np.sin(th)-yd*np.cos(th)
    B=0*th
    if 'tv' in parts: B=B+0.5*w*hdth          # velocity part of temporal
    if 'cv' in parts: B=B+0.5*w*hdth-2.4*w*hth*hd/h   # convective, velocity
    if 'cs' in parts: B=B+w*w/4*(htt-2.4*hth**2/h)   # convective, steady
    s=rho*R*L**3/12  # times c/c: B has factor c, h has c -> cancel
    return np.array([s*trap(np.cos(th)*B/h), s*trap(np.sin(th)*B/h)])
def coefs(parts):
    d=1e-6;K=np.zeros((2,2));C=np.zeros((2,2))
    for j in range(2):
        e=np.zeros(2);e[j]=d
        K[:,j]=-(Fin(np.array([X,Y])+e,np.zeros(2),parts)-Fin(np.array([X,Y])-e,np.zeros(2),parts))/(2*d*c)
        C[:,j]=-(Fin(np.array([X,Y]),e*w,parts)-Fin(np.array([X,Y]),-e*w,parts))/(2*d*w*c)
    return K,C
h=1-X*np.cos(th)-Y*np.sin(th)
cshort=mu*R*L**3/c**3*np.array([[trap(np.cos(th)**2/h**3),trap(np.cos(th)*np.sin(th)/h**3)],[0,trap(np.sin(th)**2/h**3)]])
Cfilm=np.array([[46265.5,15943.5],[15943.5,21186.4]])
kappa=(Cfilm[0,0]+Cfilm[1,1])/(cshort[0,0]+cshort[1,1])
print("kappa",kappa, "Re*",rho*w*c*c/mu)
for p in (['tv'],['cv'],['cs'],['tv','cv','cs']):
    K,C=coefs(p); print(p,"dK (MN/m)",(kappa*K/1e6).round(3).tolist(),"dC (kN s/m)",(kappa*C/1e3).round(3).tolist())
print("static inertia force N",kappa*Fin(np.array([X,Y]),np.zeros(2),['cs']))
