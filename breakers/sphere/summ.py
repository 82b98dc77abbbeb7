import json, sys
for fn in sys.argv[1:]:
    for l in open(fn):
        try: d=json.loads(l.split(' <<<')[0])
        except Exception: print(l.strip()[:200]); continue
        if 'check' not in d: print(d); continue
        print('%-26s rc=%s chk=%.3f %-12s surf=%-8s Wv=%-4.3g tb=%.3f r1=%.3f wsim=%s t/c=%.3f pass=%.1f %s' % (d['name'], d['rc'], d.get('check',0), d.get('rule'), d.get('surface'), d.get('Wv') or 0, d.get('pulse_ratio',0), d.get('rule1_ratio',0), d.get('wsim'), max(d.get('pulse_ratio',0), d.get('rule1_ratio',0))/d['check'], d.get('pass') or 0, ('BUG' if 'BUG' in l else '')))
