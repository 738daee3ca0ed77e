"""Which sources' values won a GPI run's maximum, from a results folder's summary.json
(`runs[].source_steps`: the steps each source's value won, the learner's the rest): per
run the source that won most, and per source its recorded score, its rank in the library
and its mean share of the steps a source won. Only the standard library.

    python3 scripts/winning_sources.py DIR [METHOD]     # METHOD: gpi by default
"""
import collections
import json
import sys

d=sys.argv[1]; m=sys.argv[2] if len(sys.argv)>2 else 'gpi'
s=json.load(open(f'{d}/summary.json'))
lib=s['library']; names=[e['name'] for e in lib]
scores=[e.get('final_score') for e in lib]
order=sorted(range(len(lib)), key=lambda i:-(scores[i] if scores[i] is not None else -1e9))
rank={i:r+1 for r,i in enumerate(order)}
top=collections.Counter(); shares=collections.defaultdict(list); learner=[]
for r in s['runs']:
    if r['method']!=m: continue
    st=r.get('source_steps') or []
    tot=sum(st); steps=r.get('steps') or r.get('env_steps')
    if tot==0: continue
    i=max(range(len(st)), key=lambda k: st[k]); top[i]+=1
    for k in range(len(st)): shares[k].append(st[k]/tot)
    learner.append(1-tot/steps if steps else None)
print('runs whose most-used source is:', {f'{names[i]} (score {scores[i]}, rank {rank[i]})':n for i,n in top.most_common()})
for k in sorted(shares, key=lambda k:-sum(shares[k])):
    print(f'  {names[k]:10s} rank {rank[k]:2d} score {scores[k]}  mean share of source-won steps {sum(shares[k])/len(shares[k]):.3f}')
print('  mean share of all steps a source won:', sum(1-x for x in learner)/len(learner) if learner else None)
