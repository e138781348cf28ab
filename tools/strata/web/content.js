// strata view: what the state shows (the map of a snapshot, or a diff or change set over the
// map in grey, a free-space slice, walls, vehicles, changed objects) and the URL that holds it.
'use strict';
var strata = window.strata || (window.strata = {});

strata.COLORS = ['class', 'height', 'session', 'slant'];

strata.parseHash = function (hash, manifest) {
  // Colour by class when the map has classes, else by height (a map of unlabelled scans).
  var labelled = manifest.snapshots[0].tiles.some(function (t) { return t.labelled_voxels > 0; });
  var state = { camera: null, color: labelled ? 'class' : 'height',
                session: manifest.snapshots[0].as_of_session,
                diff: null, changeset: null, free: null, ui: true,
                layers: { walls: true, vehicles: true, cleared: false } };
  var numbers = function (text) { return text.split(',').map(Number); };
  hash.replace(/^#/, '').split('&').forEach(function (pair) {
    var kv = pair.split('='), k = kv[0], v = decodeURIComponent(kv[1] || '');
    if (k === 'camera' && numbers(v).length === 6 && numbers(v).every(isFinite)) state.camera = numbers(v);
    if (k === 'color' && strata.COLORS.indexOf(v) >= 0) state.color = v;
    if (k === 'session' && isFinite(Number(v))) state.session = Number(v);
    if (k === 'diff' && numbers(v).length === 2 && numbers(v).every(isFinite)) state.diff = numbers(v);
    if (k === 'changeset' && v && isFinite(Number(v))) state.changeset = Number(v);
    if (k === 'free' && v && isFinite(Number(v))) state.free = Number(v);
    if (k === 'ui') state.ui = v !== '0';
    if (k === 'layers') {
      var on = v.split(',');
      Object.keys(state.layers).forEach(function (name) { state.layers[name] = on.indexOf(name) >= 0; });
    }
  });
  return state;
};

strata.writeHash = function (viewer) {
  var s = viewer.state, p = viewer.camera.position, t = viewer.controls.target;
  var parts = ['camera=' + [p.x, p.y, p.z, t.x, t.y, t.z].map(function (v) { return v.toFixed(2); }).join(','),
               'color=' + s.color, 'session=' + s.session];
  if (s.diff) parts.push('diff=' + s.diff.join(','));
  if (s.changeset) parts.push('changeset=' + s.changeset);
  if (s.free !== null) parts.push('free=' + s.free.toFixed(2));
  parts.push('layers=' + Object.keys(s.layers).filter(function (k) { return s.layers[k]; }).join(','));
  if (!s.ui) parts.push('ui=0');
  history.replaceState(null, '', '#' + parts.join('&'));
};

function tileBox(snapshot, x, y, voxelM, tileVoxels) {
  var t = snapshot.tiles.find(function (t) { return t.x === x && t.y === y; });
  if (t) return { min: t.min, max: t.max };
  var s = voxelM * tileVoxels;
  return { min: [x * s, y * s, -50], max: [(x + 1) * s, (y + 1) * s, 50] };
}

strata.Viewer.prototype.setScale = function (object) {
  var scale = this.pixelScale();
  object.traverse(function (o) {
    if (o.material && o.material.uniforms && o.material.uniforms.scale) o.material.uniforms.scale.value = scale;
  });
  return object;
};

// A map tile: its cells in the colour mode (grey under a diff), cleared vehicle voxels apart.
strata.Viewer.prototype.mapBuilder = function (context) {
  var viewer = this, F = strata.FLAGS;
  return function (cells) {
    var group = new THREE.Group();
    var solid = strata.buildPoints(cells, function (i) { return !(cells.flags[i] & F.cleared); },
                                   viewer.colorFunction(context), 1);
    solid.userData.kind = 'map';
    solid.userData.context = context;
    var cleared = strata.buildPoints(cells, function (i) { return cells.flags[i] & F.cleared; },
                                     function (c, i, out) { return strata.copy(strata.VEHICLE_BOX, out); }, 0.45);
    cleared.userData.kind = 'cleared';
    cleared.visible = viewer.state.layers.cleared;
    group.add(solid, cleared);
    group.userData.cellCount = cells.count;
    return viewer.setScale(group);
  };
};

strata.Viewer.prototype.changeBuilder = function () {
  var viewer = this;
  return function (cells) {
    var points = strata.buildPoints(cells, function () { return true; }, function (c, i, out) {
      return strata.copy(c.flags[i] & strata.FLAGS.added ? strata.ADDED : strata.REMOVED, out);
    }, 1, 2e-4);  // drawn over the map's own cells at the same place
    points.userData.kind = 'change';
    points.userData.cellCount = cells.count;
    return viewer.setScale(points);
  };
};

strata.Viewer.prototype.tileSet = function (name, tiles, build) {
  if (this.sets[name]) this.sets[name].dispose();
  var set = new strata.TileSet(this.groups[name], tiles, this.manifest.max_lod, this.voxelM, build);
  var viewer = this;
  set.onchange = function () { viewer.dirty = true; set.request(); };
  this.sets[name] = set;
  this.moved = true;
};

strata.Viewer.prototype.apply = function () {
  var s = this.state, viewer = this, m = this.manifest;
  var key = JSON.stringify([s.session, s.diff, s.changeset]);
  var snapshot = s.diff ? (m.snapshots.find(function (x) { return x.as_of_session === s.diff[1]; }) ||
                           m.snapshots[0])
                        : s.changeset ? m.snapshots[0] : this.snapshot();
  var context = !!(s.diff || s.changeset);
  if (key !== this.contentKey) {
    this.contentKey = key;
    this.freeKey = null;
    this.shown = snapshot;
    this.tileSet('map', snapshot.tiles.map(function (t) {
      return { min: t.min, max: t.max, path: function (lod) {
        return '/api/tile/' + t.x + '/' + t.y + '/' + t.version + '/' + lod; } };
    }), this.mapBuilder(context));
    if (this.sets.change) { this.sets.change.dispose(); delete this.sets.change; }
    this.overlays.changes.show([]);
    this.changeReport = null;
    if (context) this.loadChange(snapshot);
    this.overlays.walls.show(m.walls.filter(function (w) { return w.commit <= snapshot.commit; })
                                .map(strata.wallObject));
    this.overlays.vehicles.show(m.vehicles.filter(function (v) { return v.commit <= snapshot.commit; })
                                   .map(strata.vehicleObject));
    this.ui.describe((s.diff ? 'session ' + s.diff[0] + ' → ' + s.diff[1] + ' over ' : '') +
                     (s.changeset ? 'change set #' + s.changeset + ' over ' : '') +
                     'commit ' + snapshot.commit + ' · ' + snapshot.tiles.length + ' tiles');
  } else {
    var color = this.colorFunction(context);
    this.groups.map.traverse(function (o) {
      if (o.userData.kind === 'map') strata.recolor(o, color);
      if (o.userData.kind === 'cleared') o.visible = s.layers.cleared;
    });
  }
  this.applyFree(snapshot);
  this.overlays.walls.group.visible = s.layers.walls;
  this.overlays.vehicles.group.visible = s.layers.vehicles;
  this.ui.update();
  strata.writeHash(this);
  this.dirty = this.moved = true;
};

// The changed voxels of a diff or saved change set, and the boxes of its objects.
strata.Viewer.prototype.loadChange = function (snapshot) {
  var s = this.state, viewer = this, key = this.contentKey;
  var base = s.diff ? '/api/diff/' + s.diff[0] + '/' + s.diff[1] : '/api/changeset/' + s.changeset;
  this.pendingChange = true;
  strata.load(base, false).then(function (summary) {
    if (viewer.contentKey !== key) return;
    var report = s.diff ? summary.report : (summary.record || {}).report || {};
    viewer.changeReport = report;
    var sides = { from: report.from, to: report.to };
    viewer.overlays.changes.show((report.objects || []).map(function (o) { return strata.changeObject(o, sides); }));
    viewer.tileSet('change', summary.tiles.map(function (xy) {
      var b = tileBox(snapshot, xy[0], xy[1], viewer.voxelM, viewer.manifest.map.tile_voxels);
      return { min: b.min, max: b.max, path: function (lod) { return base + '/' + xy[0] + '/' + xy[1] + '/' + lod; } };
    }), viewer.changeBuilder());
    if (!summary.voxels) viewer.ui.describe('change set #' + s.changeset + ': its voxels cannot be rebuilt; boxes only');
  }).catch(function (error) {
    viewer.ui.status(String(error));
  }).then(function () {
    viewer.pendingChange = false;
    viewer.dirty = viewer.moved = true;
  });
};

// A slice of observed free space one cell thick at height state.free (needs the server).
strata.Viewer.prototype.applyFree = function (snapshot) {
  var z = this.state.free, viewer = this;
  var key = z === null || strata.isStatic() ? null : JSON.stringify([z, snapshot.commit]);
  if (key === this.freeKey) return;
  this.freeKey = key;
  if (this.sets.free) { this.sets.free.dispose(); delete this.sets.free; }
  if (key === null) return;
  this.tileSet('free', snapshot.tiles.map(function (t) {
    return { min: [t.min[0], t.min[1], z - 1], max: [t.max[0], t.max[1], z + 1], path: function (lod) {
      var slab = Math.floor(z / (viewer.voxelM * (1 << lod)));
      return '/api/free/' + t.x + '/' + t.y + '/' + t.version + '/' + lod + '/' + slab; } };
  }), function (cells) {
    var points = strata.buildPoints(cells, function () { return true; }, function (c, i, out) {
      return strata.copy([120, 190, 255], out);
    }, 0.3);
    points.userData.kind = 'free';
    points.userData.cellCount = cells.count;
    return viewer.setScale(points);
  });
};
