"""Pairs two sets of study runs by seed, whatever their settings (layer on/off, layer parameters).

    python3 pair_any.py NEW.csv[,NEW2.csv] OLD.csv[,OLD2.csv]

Prints, for the seeds both have: the mean per run of each, and the paired difference NEW - OLD
as mean ± standard error.
"""
import csv,statistics as st,sys
def load(fs):
    d={}
    for f in fs.split(','):
        for r in csv.DictReader(open(f)): d[r['seed']]=r
    return d
a=load(sys.argv[1]); b=load(sys.argv[2])
ks=sorted(set(a)&set(b),key=int); print(len(ks),'paired seeds', ks[0],'-',ks[-1])
for c in ['tasks','efficiency','robot_caused_contacts','person_caused_contacts','robot_robot_contacts','wall_contacts','total_contacts','min_human_distance_m','human_delay_s','stuck_robot_s','gridlocks','deadlocks']:
    d=[float(a[k][c])-float(b[k][c]) for k in ks]
    print(f"| {c} | {st.mean(float(a[k][c]) for k in ks):.3f} | {st.mean(float(b[k][c]) for k in ks):.3f} | {st.mean(d):+.2f} ± {st.stdev(d)/len(d)**.5:.2f} |")
