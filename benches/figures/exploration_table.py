"""The table of docs/exploration.md, "Exploration against its ceiling", from a sweep run with
oracle = true (examples/sweeps/exploration_quick.toml): per setting, views per object, coverage,
coverage / ceiling, objects at 95 % of their ceiling, wasted views, views after the last
rise of 0.5 point, the same views without noise, F-score; with the self-calibration on,
the hand-eye estimate's error and the views it read (those taken for it alone apart). Usage:
    python3 benches/figures/exploration_table.py SWEEP_DIR [-v]
"""
import json,glob,sys,collections
d=sys.argv[1]
groups=collections.defaultdict(list)
for rowf in sorted(glob.glob(d+'/episodes/*.row.json')):
    row=json.load(open(rowf))
    key=tuple((k,v) for k,v in row['params'] if k not in ('registration.calibrate_hand_eye','registration.baselines'))
    rep=json.load(open(rowf.replace('.row.json','/report.json')))
    groups[key].append((row,rep))
for key,items in groups.items():
    objs=[];eps=len(items);coll=0;split=0;missed=0;phant=0;times=[];he=[]
    for row,rep in items:
        coll+=rep['totals']['collisions']; split+=len(rep['split_objects']); missed+=len(rep['missed_objects']); phant+=rep['phantom_clusters']
        times.append(row['time_s'])
        h=rep.get('hand_eye')
        if h and h.get('translation_error') is not None:
            he.append((h['rotation_error_deg'],h['translation_error']*1e3,h['estimate']['views'],sum(o.get('calibration_views',0) for o in rep['objects'])))
        for o in rep['objects']:
            if o.get('oracle') is None: continue
            e=o['oracle']
            objs.append(dict(name=o['name'],scene=row['scene'],v=len(o['views']),cc=e['coverage_of_ceiling'],cov=o['coverage'],ceil=e['ceiling'],v95=e['views_to_95'],o95=e['oracle_views_to_95'],w=o['wasted_views'],after=o['views_after_last_rise'],nf=(e['noise_free_by_view'] or [0])[-1],f=o['quality']['f_score'] if o['quality'] else 0))
    n=len(objs)
    reached=[o for o in objs if o['v95'] is not None]
    ratio=max([o['v95']/max(o['o95'],1) for o in reached] or [0])
    over=sum(1 for o in objs if o['v95'] is None or o['v95']>2*max(o['o95'],1))
    print(key)
    print('  episodes %d objects %d | views/obj %.2f | cov %.3f | ceil %.3f | cov/ceil mean %.3f min %.3f | >=95%% of ceiling %d/%d | v95/o95 max %.1f, over 2x %d | wasted/obj %.2f | after-rise max %d mean %.2f (<=2: %d/%d) | noise-free same views %.3f | F %.3f | coll %d split %d missed %d phantom %d | time/ep %.0f s'%(
        eps,n,sum(o['v'] for o in objs)/n,sum(o['cov'] for o in objs)/n,sum(o['ceil'] for o in objs)/n,sum(o['cc'] for o in objs)/n,min(o['cc'] for o in objs),len(reached),n,ratio,over,sum(o['w'] for o in objs)/n,max(o['after'] for o in objs),sum(o['after'] for o in objs)/n,sum(1 for o in objs if o['after']<=2),n,sum(o['nf'] for o in objs)/n,sum(o['f'] for o in objs)/n,coll,split,missed,phant,sum(times)/len(times)))
    if he:
        k=len(he)
        print('  hand-eye: rotation off mean %.3f worst %.3f deg (within 0.1: %d/%d) | translation off mean %.2f worst %.2f mm (within 1 mm: %d/%d) | views read %.1f, taken for it %.1f per episode'%(
            sum(x[0] for x in he)/k,max(x[0] for x in he),sum(x[0]<0.1 for x in he),k,sum(x[1] for x in he)/k,max(x[1] for x in he),sum(x[1]<1 for x in he),k,sum(x[2] for x in he)/k,sum(x[3] for x in he)/k))
    if '-v' in sys.argv:
        for o in objs: print('     %-22s %-12s v=%2d cov %.3f ceil %.3f cc %.3f v95 %s o95 %d w %d after %d nf %.3f'%(o['scene'][:22],o['name'],o['v'],o['cov'],o['ceil'],o['cc'],o['v95'],o['o95'],o['w'],o['after'],o['nf']))
