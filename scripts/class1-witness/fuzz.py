import json, math, os, random, subprocess, sys
HERE=os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0,HERE)
GL=os.environ.get('GAZE_LIDAR',os.path.join(HERE,'..','..','target','release','gaze-lidar'))
ORACLE=os.environ.get('ORACLE',os.path.join(HERE,'target','release','class1-witness'))
OUT=os.environ.get('OUT','/tmp')
from gen import prof
seed=int(sys.argv[1]); N=int(sys.argv[2]); random.seed(seed)
def checker(path):
    r=subprocess.run([GL,'check','--format','json',path],capture_output=True,text=True)
    try: d=json.loads(r.stdout.splitlines()[0])
    except Exception: return None, r.stderr.strip()[:200]
    if d.get('certified'): return d['eye_safety']['worst_ratio'], 'cert:'+str(d['eye_safety']['binding_rule'])
    for v in d['violations']:
        if v['detail'].get('kind')=='eye_safety': return v['detail']['ratio'], 'rej'
    return None, str([v['message'][:120] for v in d['violations']])
for case in range(N):
    fam=random.choice(['hot','accel','locked','slow','ir','wide','tiny'])
    lam=random.choice([905.0,905.0,850.0,1450.0,1550.0]) if fam!='ir' else random.choice([1450.0,1550.0,1499.0,1400.0])
    tau=10**random.uniform(-9,-7.5)
    beam=random.uniform(0.5,10.0) if fam!='wide' else random.uniform(300,640)
    nb=random.randint(2,7)
    ws=[random.uniform(0.2,1.0) for _ in range(nb)]
    if fam in ('hot','tiny'):
        k=random.randrange(nb); ws[k]=random.choice([1e-3,0.01,0.05]) if fam=='tiny' else random.uniform(0.003,0.03)
    s=sum(ws); ws=[360*w/s for w in ws]
    base=random.uniform(20,300)
    bins=[]
    prev=None
    for i,w in enumerate(ws):
        if fam=='accel':
            w0=prev if prev else random.uniform(0.5,1.5)*base
            w1=random.choice([random.uniform(0.02,1.5)*base, 1e-3*base])
            prev=w1
        elif fam=='slow':
            w0=w1=random.uniform(0.005,0.5)
        else:
            w0=w1=random.uniform(0.15,1.5)*base
        p=random.choice([0.0,random.uniform(0.1,1.0),1.0])
        bins.append([w,p,w0,w1])
    if fam=='accel': bins[0][2]=bins[-1][3]
    # frame period
    T=sum(2*math.radians(b[0])/(b[2]+b[3]) for b in bins)
    if fam=='locked':
        f=random.randint(50,3000)/T
    else:
        f=10**random.uniform(1.5,4.8)
    if fam=='slow': f=10**random.uniform(0,2.5)
    if f*tau>=0.5: tau=0.1/f
    # estimate pulse count in 100 s
    h=(7+beam)/200
    est=f*min(100,T*max(1,100/T))*min(1,2*h/(2*math.pi))*4
    if est>4e5: continue
    d=prof([tuple(b) for b in bins],f,lam,tau,beam)
    path=os.path.join(OUT,f'c_{seed}_{case}.json')
    json.dump(d,open(path,'w'))
    import os
    if os.environ.get('ONLY') and str(case)!=os.environ['ONLY']: continue
    r,msg=checker(path)
    if r is None or r<=0: continue
    k=0.999/r
    for b in d['bins']: b['power_w']*=k
    d['limits']['power_w_max']*=k; d['average_power_w']*=k
    json.dump(d,open(path,'w'))
    r2,msg=checker(path)
    try:
        o=subprocess.run(['timeout','120',ORACLE,path,'48','2','400000'],capture_output=True,text=True).stdout.strip()
        orat=float(o.split()[2])
    except Exception as e:
        print(case,fam,'oracle fail',e,flush=True); continue
    flag='!!!' if orat>r2*(1+1e-9) else ''
    print(case,fam,lam,'checker',r2,msg,'oracle',o,flag,flush=True)
    if not flag: 
        import os; os.remove(path)
