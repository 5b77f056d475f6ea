#!/usr/bin/env python3
"""Where a network's drapes differ from the simulator's: analyses of `garnet eval
--save-drapes DIR` output (DIR/MODEL/INDEX-{net,sim,dqs,body}.ply in metres and
DIR/MODEL/samples.csv), read against the dataset's manifest. Needs numpy (and scipy for
`scales`). Lengths are reported in cm.

  drape_errors.py by-stat DRAPES DATASET   E_dist by quartile of the manifest's statistics
  drape_errors.py shrink  DRAPES DATASET   how far the network moves the cloth from M
  drape_errors.py scales  DRAPES           the error field's smooth part and what is left
  drape_errors.py regions DRAPES TEMPLATE  E_dist by region of the garment (each vertex's
                                           dominant skinning bone in TEMPLATE, a .garment file)
  drape_errors.py contact DRAPES           the error along and across the body normal, and
                                           E_dist with each vertex's clearance from the skin
                                           made exact (the ceiling of a contact correction)
  drape_errors.py smooth  DRAPES           E_dist with the predicted displacement from M
                                           smoothed over the mesh, 1 to 16 iterations
  drape_errors.py noise DATASET DRAPES OTHER...
                                           how much of E_dist is the labels' own spread: OTHER
                                           are the same model's drapes of the same samples
                                           simulated again with a negligible change (say the
                                           cloth 0.1% heavier); the network against each label
                                           set and their mean, the labels against each other
                                           (E_dist and E_norm), and the split into label spread
                                           and network error, by motion too (DATASET's
                                           manifest names them)
  drape_errors.py shared A B A2 B2         how much of their error two models share, and
                                           what averaging them can gain: A and B are their
                                           drapes of one label set, A2 and B2 of the same
                                           samples simulated again (as for `noise`); blends
                                           w A + (1 - w) B, the correlation of the two
                                           models' own errors (the labels' spread taken
                                           out) and the floor of an ensemble of such models
"""
import csv
import glob
import json
import struct
import sys

import numpy as np


def read_ply(path, faces=False):
    """Vertices [N, 3] (and faces [F, 3] with faces=True) of a binary PLY written by garnet."""
    data = open(path, 'rb').read()
    head, _, body = data.partition(b'end_header\n')
    lines = head.split(b'\n')
    count = lambda name: int([l for l in lines if l.startswith(b'element ' + name)][0].split()[2])
    n = count(b'vertex')
    v = np.frombuffer(body[:n * 12], dtype='<f4').reshape(n, 3).astype(np.float64)
    if not faces:
        return v
    rec = np.dtype([('count', 'u1'), ('index', '<i4', (3,))])
    return v, np.frombuffer(body[n * 12:], dtype=rec, count=count(b'face'))['index']


class Drapes:
    """One model's saved drapes and, optionally, the dataset's manifest entries."""

    def __init__(self, folder, dataset=None):
        self.dir = glob.glob(folder.rstrip('/') + '/*/')[0]
        self.rows = list(csv.DictReader(open(self.dir + 'samples.csv')))
        self.samples = {}
        if dataset:
            manifest = json.load(open(dataset.rstrip('/') + '/manifest.json'))
            self.samples = {s['index']: s for s in manifest['samples']}

    def mesh(self, index, kind):
        return read_ply(f'{self.dir}{index:06d}-{kind}.ply')

    def each(self):
        """(index, net, sim, dqs) of every drape."""
        for r in self.rows:
            k = int(r['index'])
            yield k, self.mesh(k, 'net'), self.mesh(k, 'sim'), self.mesh(k, 'dqs')


def dist_cm(a, b):
    """Per-vertex distance [N] between two meshes of one topology, cm."""
    return 100 * np.linalg.norm(a - b, axis=1)


def mean_dist_cm(a, b):
    return dist_cm(a, b).mean()


def quartile_table(key, values, errors):
    q = np.quantile(values, [0, .25, .5, .75, 1])
    cells = [errors[(values >= lo) & (values <= hi)].mean() for lo, hi in zip(q[:-1], q[1:])]
    print(f"{key:22s} " + ' '.join(f'{c:6.3f}' for c in cells) +
          f"   corr {np.corrcoef(values, errors)[0, 1]:5.2f}")


def by_stat(drapes):
    k = [int(r['index']) for r in drapes.rows]
    e = np.array([float(r['e_dist_cm']) for r in drapes.rows])
    stat = lambda f: np.array([f(drapes.samples[i]) for i in k])
    print('E_dist (cm) by quartile, lowest to highest')
    quartile_table('slid_m', stat(lambda s: s['stats']['slid_m']), e)
    quartile_table('DQS E_dist', np.array([float(r['dqs_e_dist_cm']) for r in drapes.rows]), e)
    quartile_table('strain p99', stat(lambda s: s['stats']['strain_p99']), e)
    quartile_table('bmi', stat(lambda s: s['bmi']), e)
    quartile_table('stature', stat(lambda s: s['stature_m']), e)
    rest = stat(lambda s: s['stats']['converged'])
    print(f'came to rest: {rest.sum()} drapes, {e[rest].mean():.3f} cm; '
          f'still moving: {(~rest).sum()} drapes, {e[~rest].mean():.3f} cm')


def shrink(drapes):
    res = []
    for k, net, sim, dqs in drapes.each():
        true, pred = sim - dqs, net - dqs
        res.append((drapes.samples[k]['stats']['slid_m'], mean_dist_cm(sim, dqs),
                    mean_dist_cm(net, dqs), (true * pred).sum() / (true * true).sum(),
                    mean_dist_cm(net, sim)))
    a = np.array(res)
    q = np.quantile(a[:, 0], [0, .25, .5, .75, 1])
    print('slid (m)       |G-M|  |net-M|  projection  E_dist (cm)')
    for lo, hi in zip(q[:-1], q[1:]):
        s = (a[:, 0] >= lo) & (a[:, 0] <= hi)
        print(f'{lo:.3f}-{hi:.3f}  {a[s, 1].mean():5.2f}  {a[s, 2].mean():6.2f}  '
              f'{a[s, 3].mean():10.2f}  {a[s, 4].mean():6.3f}')
    for scale in (0.95, 1.0, 1.03, 1.06, 1.1):
        e = [mean_dist_cm(dqs + scale * (net - dqs), sim) for _, net, sim, dqs in drapes.each()]
        print(f'displacement scaled by {scale:.2f}: E_dist {np.mean(e):.4f} cm')


def ring_mean(drapes):
    """The garment's 1-ring mean as a sparse [N, N] matrix (row i averages i's neighbours)."""
    import scipy.sparse as sp
    _, faces = read_ply(drapes.dir + f"{int(drapes.rows[0]['index']):06d}-sim.ply", True)
    n = faces.max() + 1
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    edges = np.unique(np.concatenate([edges, edges[:, ::-1]]), axis=0)
    ring = sp.csr_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    return sp.diags(1 / np.asarray(ring.sum(1)).ravel()) @ ring


def scales(drapes):
    ring = ring_mean(drapes)
    marks = (5, 20, 80, 320)
    parts = {m: [] for m in marks}
    for _, net, sim, _ in drapes.each():
        err = net - sim
        smooth, done = err.copy(), 0
        for m in marks:
            while done < m:
                smooth, done = 0.5 * smooth + 0.5 * (ring @ smooth), done + 1
            parts[m].append((mean_dist_cm(smooth, 0), mean_dist_cm(err - smooth, 0)))
    for m in marks:
        a = np.array(parts[m])
        print(f'{m:3d} iterations: smoothed part {a[:, 0].mean():.2f} cm, '
              f'remainder {a[:, 1].mean():.2f} cm')


def dominant_bones(template):
    """Name of the bone with the largest skinning weight, per vertex of a `.garment` file
    (safetensors: `weights.offsets` [N+1], `weights.bones` and `weights.values` per entry).
    The header is read by hand (8-byte length, JSON) so that the script needs numpy alone,
    not the `safetensors` package, for three small arrays."""
    data = open(template, 'rb').read()
    size = struct.unpack('<Q', data[:8])[0]
    head = json.loads(data[8:8 + size])

    def tensor(name, dtype):
        start, end = head[name]['data_offsets']
        return np.frombuffer(data[8 + size + start:8 + size + end], dtype=dtype)

    names = [b['name'] for b in json.loads(head['__metadata__']['bones'])]
    offsets, bones = tensor('weights.offsets', '<u4'), tensor('weights.bones', '<u2')
    values = tensor('weights.values', '<f4')
    return [names[bones[a:b][np.argmax(values[a:b])]] for a, b in zip(offsets[:-1], offsets[1:])]


def regions(drapes, template):
    limb = lambda b: any(part in b for part in ('Shoulder', 'Arm', 'Hand'))
    region = np.array([('left arm' if b.startswith('L') else 'right arm') if limb(b) else b
                       for b in dominant_bones(template)])
    err = np.array([100 * np.linalg.norm(net - sim, axis=1) for _, net, sim, _ in drapes.each()])
    print(f'{len(err)} drapes, E_dist {err.mean():.3f} cm')
    for name in sorted(set(region), key=lambda r: -(region == r).sum()):
        m = region == name
        print(f'{name:12s} {m.sum():5d} vertices  E_dist {err[:, m].mean():.3f} cm  '
              f'share of the error {100 * err[:, m].sum() / err.sum():4.1f}%')


def vertex_normals(v, f):
    """Unit area-weighted vertex normals [N, 3] of a mesh."""
    fn = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    n = np.zeros_like(v)
    for k in range(3):
        np.add.at(n, f[:, k], fn)
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)


def nearest_vertex(points, queries, chunk=512):
    """Index of the nearest of `points` [V, 3] to each of `queries` [Q, 3] (brute force)."""
    out = np.empty(len(queries), dtype=np.int64)
    pp = (points ** 2).sum(1)
    for s in range(0, len(queries), chunk):
        q = queries[s:s + chunk]
        out[s:s + chunk] = ((q ** 2).sum(1)[:, None] - 2 * q @ points.T + pp[None, :]).argmin(1)
    return out


def contact(drapes, near=0.02):
    """Each predicted vertex moved along the body normal at its nearest body vertex until its
    clearance from the skin is the simulated vertex's (at that one's nearest body vertex):
    E_dist with every vertex so corrected, and with only those whose simulated position is
    within `near` metres of the skin."""
    res = []
    for k, net, sim, _ in drapes.each():
        body, faces = read_ply(f'{drapes.dir}{k:06d}-body.ply', faces=True)
        normals = vertex_normals(body, faces)
        i_net, i_sim = nearest_vertex(body, net), nearest_vertex(body, sim)
        n = normals[i_net]
        clear_net = ((net - body[i_net]) * n).sum(1)
        clear_sim = ((sim - body[i_sim]) * normals[i_sim]).sum(1)
        along = ((net - sim) * n).sum(1)
        across = np.linalg.norm(net - sim - along[:, None] * n, axis=1)
        fixed = net + (clear_sim - clear_net)[:, None] * n
        touching = clear_sim < near
        res.append((mean_dist_cm(net, sim), mean_dist_cm(fixed, sim),
                    mean_dist_cm(np.where(touching[:, None], fixed, net), sim),
                    100 * np.abs(along).mean(), 100 * across.mean(), touching.mean()))
    a = np.array(res).mean(0)
    print(f'{len(res)} drapes: E_dist {a[0]:.3f} cm; clearance made exact everywhere '
          f'{a[1]:.3f} cm, only within {100 * near:.0f} cm of the skin ({100 * a[5]:.0f}% of '
          f'the vertices) {a[2]:.3f} cm; error along the body normal {a[3]:.3f} cm, across '
          f'{a[4]:.3f} cm')


def smooth(drapes, weights=(0.05, 0.1, 0.25, 0.5)):
    """E_dist with the network's displacement from M (net - dqs) smoothed over the mesh by 1
    to 16 iterations, each moving a vertex's displacement the given weight of the way to its
    1-ring's mean: does the prediction carry high-frequency noise that the labels lack?"""
    ring = ring_mean(drapes)
    marks = (1, 2, 4, 8, 16)
    res = {(w, m): [] for w in weights for m in marks}
    raw = []
    for _, net, sim, dqs in drapes.each():
        raw.append(mean_dist_cm(net, sim))
        for w in weights:
            d, done = net - dqs, 0
            for m in marks:
                while done < m:
                    d, done = (1 - w) * d + w * (ring @ d), done + 1
                res[(w, m)].append(mean_dist_cm(dqs + d, sim))
    print(f'{len(raw)} drapes: E_dist {np.mean(raw):.4f} cm as predicted')
    for w in weights:
        print(f'weight {w}: ' + ', '.join(f'{m} iterations {np.mean(res[(w, m)]):.4f}'
                                          for m in marks))


def e_norm_deg(a, b, f):
    """E_norm: the mean angle between the two meshes' face normals, degrees."""
    na = np.cross(a[f[:, 1]] - a[f[:, 0]], a[f[:, 2]] - a[f[:, 0]])
    nb = np.cross(b[f[:, 1]] - b[f[:, 0]], b[f[:, 2]] - b[f[:, 0]])
    angle = np.arctan2(np.linalg.norm(np.cross(na, nb), axis=1), (na * nb).sum(axis=1))
    return np.degrees(angle).mean()


def noise(drapes, others, scales=(0.5, 0.75, 0.9, 1.0)):
    """Splits the network's error into the labels' spread and its own. With K label sets of
    the same samples, each label the expected drape plus an independent spread s (per-vertex
    RMS), and e the network's RMS distance from the expected drape: RMS(net, one label)^2 =
    e^2 + s^2 and RMS(label, label)^2 = 2 s^2, so a network that drew the expected drape
    exactly would still be s from the labels. Also E_dist with the network's error about the
    labels' mean scaled by each of `scales` (mean + k (net - mean), each label as it is):
    what a network with k times its own error would score."""
    sets = [drapes] + others
    common = sorted(set.intersection(*({int(r['index']) for r in d.rows} for d in sets)))
    k = len(sets)
    names = ('net', 'net_mean', 'pair', 'net_rms', 'net_mean_rms', 'pair_rms', 'net_norm',
             'pair_norm') + tuple(f'scaled {c}' for c in scales)
    stats = {name: [] for name in names}
    faces = None
    motions = {}
    for index in common:
        net = drapes.mesh(index, 'net')
        if faces is None:
            faces = read_ply(f'{drapes.dir}{index:06d}-sim.ply', faces=True)[1]
        labels = [d.mesh(index, 'sim') for d in sets]
        mean = np.mean(labels, axis=0)
        to_label = [dist_cm(net, g) for g in labels]
        to_mean = dist_cm(net, mean)
        pairs = [(a, b) for i, a in enumerate(labels) for b in labels[i + 1:]]
        between = [dist_cm(a, b) for a, b in pairs]
        stats['net'].append(np.mean([d.mean() for d in to_label]))
        stats['net_rms'].append(np.mean([(d ** 2).mean() for d in to_label]))
        stats['net_mean'].append(to_mean.mean())
        stats['net_mean_rms'].append((to_mean ** 2).mean())
        stats['pair'].append(np.mean([d.mean() for d in between]))
        stats['pair_rms'].append(np.mean([(d ** 2).mean() for d in between]))
        stats['net_norm'].append(np.mean([e_norm_deg(g, net, faces) for g in labels]))
        stats['pair_norm'].append(np.mean([e_norm_deg(a, b, faces) for a, b in pairs]))
        for c in scales:
            scaled = mean + c * (net - mean)
            stats[f'scaled {c}'].append(np.mean([dist_cm(scaled, g).mean() for g in labels]))
        motion = drapes.samples.get(index, {}).get('pose', '?').split('#')[0]
        motion = motion.split(':')[-1] if motion.startswith('procedural') else \
            motion.rsplit('/', 1)[-1].replace('.amc', '')
        motions.setdefault(motion, []).append(len(stats['net']) - 1)
    mean = {key: np.mean(v) for key, v in stats.items()}
    spread2 = mean['pair_rms'] / 2
    print(f'{len(common)} drapes, {k} label sets')
    print(f"E_dist, network to one label (mean over the sets): {mean['net']:.3f} cm")
    print(f"E_dist, network to the mean of the {k} labels:      {mean['net_mean']:.3f} cm")
    print(f"E_dist, label to label:                             {mean['pair']:.3f} cm")
    print(f"E_norm, network to one label: {mean['net_norm']:.2f} degrees; label to label: "
          f"{mean['pair_norm']:.2f}")
    print(f"per-vertex RMS: network to a label {np.sqrt(mean['net_rms']):.3f}, to the mean "
          f"{np.sqrt(mean['net_mean_rms']):.3f}, label to label {np.sqrt(mean['pair_rms']):.3f} cm")
    print(f"a network drawing the expected drape would score about {mean['pair'] / np.sqrt(2):.3f}"
          f" cm E_dist (label to label / sqrt 2)")
    print(f"label spread s {np.sqrt(spread2):.3f} cm, the network's own error e "
          f"{np.sqrt(max(mean['net_rms'] - spread2, 0)):.3f} cm (per-vertex RMS)")
    print('E_dist with the own error scaled by k: ' +
          ', '.join(f"k {c}: {mean[f'scaled {c}']:.3f}" for c in scales) + ' cm')
    print('by motion: drapes, network to a label, to the mean, label to label (cm)')
    for motion, idx in sorted(motions.items()):
        cell = lambda key: np.mean([stats[key][i] for i in idx])
        print(f"  {motion:18s} {len(idx):4d} {cell('net'):6.3f} {cell('net_mean'):6.3f} "
              f"{cell('pair'):6.3f}")


def shared(a, b, a2, b2, weights=(1.0, 0.9, 0.8, 0.7, 0.6, 0.5)):
    """Two models' errors against one label set (a, b) and a second, independent one (a2,
    b2: the same models, the same samples simulated again). The labels' spreads are
    independent, so the mean dot product of model A's error against one set with model B's
    against the other holds their own errors only (A with itself: its own error squared).
    Averaging K models whose own errors correlate r pairwise leaves sqrt(r + (1 - r) / K)
    of one's own error, never less than sqrt(r)."""
    blends = {w: [] for w in weights}
    per_drape = []
    dot = {'aa': 0.0, 'bb': 0.0, 'ab': 0.0, 'labels': 0.0}
    count = 0
    for row in a.rows:
        index = int(row['index'])
        net_a, net_b = a.mesh(index, 'net'), b.mesh(index, 'net')
        label, label2 = a.mesh(index, 'sim'), a2.mesh(index, 'sim')
        for w in weights:
            blends[w].append(mean_dist_cm(w * net_a + (1 - w) * net_b, label))
        per_drape.append((mean_dist_cm(net_a, label), mean_dist_cm(net_b, label)))
        ea, eb = net_a - label, net_b - label
        ea2, eb2 = a2.mesh(index, 'net') - label2, b2.mesh(index, 'net') - label2
        dot['aa'] += (ea * ea2).sum()
        dot['bb'] += (eb * eb2).sum()
        dot['ab'] += ((ea * eb2).sum() + (ea2 * eb).sum()) / 2
        dot['labels'] += ((label - label2) ** 2).sum() / 2
        count += len(net_a)
    own = {key: value / count * 1e4 for key, value in dot.items()}
    r = own['ab'] / np.sqrt(own['aa'] * own['bb'])
    print(f'{len(per_drape)} drapes; E_dist of w A + (1 - w) B against the first labels:')
    for w in weights:
        print(f'  w {w:.1f}: {np.mean(blends[w]):.3f} cm')
    print(f'per-drape E_dist of A and B correlate {np.corrcoef(np.array(per_drape).T)[0, 1]:.3f}')
    print(f"own error (per-vertex RMS): A {np.sqrt(own['aa']):.3f} cm, B {np.sqrt(own['bb']):.3f} "
          f"cm; the labels' spread {np.sqrt(own['labels']):.3f} cm")
    print(f'the two own errors correlate {r:.3f}: an ensemble of models that differ as much '
          f"keeps at least {np.sqrt(max(r, 0)):.3f} of A's own error, "
          f"{np.sqrt(max(r, 0) * own['aa']):.3f} cm")


if __name__ == '__main__':
    commands = {'by-stat': by_stat, 'shrink': shrink, 'scales': scales, 'contact': contact,
                'smooth': smooth}
    if len(sys.argv) == 4 and sys.argv[1] == 'regions':
        regions(Drapes(sys.argv[2]), sys.argv[3])
    elif len(sys.argv) >= 5 and sys.argv[1] == 'noise':
        noise(Drapes(sys.argv[3], sys.argv[2]), [Drapes(d) for d in sys.argv[4:]])
    elif len(sys.argv) == 6 and sys.argv[1] == 'shared':
        shared(*(Drapes(d) for d in sys.argv[2:]))
    elif len(sys.argv) >= 3 and sys.argv[1] in commands:
        commands[sys.argv[1]](Drapes(sys.argv[2], sys.argv[3] if len(sys.argv) > 3 else None))
    else:
        sys.exit(__doc__)
