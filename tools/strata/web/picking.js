// strata view: a click shows the record of what is under the pointer: a wall, vehicle or
// changed object (its catalog row), or a voxel (every value the map keeps there; a coarse cell
// shows what its voxels share).
'use strict';
var strata = window.strata || (window.strata = {});

strata.installPicking = function (viewer) {
  var down = null;
  viewer.canvas.addEventListener('pointerdown', function (e) { down = [e.clientX, e.clientY]; });
  viewer.canvas.addEventListener('pointerup', function (e) {
    if (e.button === 0 && down && Math.abs(e.clientX - down[0]) + Math.abs(e.clientY - down[1]) < 5) {
      viewer.pickAt(e.clientX, e.clientY);
    }
    down = null;
  });
};

// Canvas pixel of a map-frame point (for tests and the docs' screenshots).
strata.Viewer.prototype.project = function (x, y, z) {
  var v = new THREE.Vector3(x, y, z).project(this.camera), r = this.canvas.getBoundingClientRect();
  return { x: r.left + (v.x + 1) / 2 * r.width, y: r.top + (1 - v.y) / 2 * r.height, visible: v.z < 1 };
};

strata.Viewer.prototype.pickAt = function (clientX, clientY) {
  var r = this.canvas.getBoundingClientRect();
  var ndc = new THREE.Vector2((clientX - r.left) / r.width * 2 - 1, 1 - (clientY - r.top) / r.height * 2);
  var ray = new THREE.Raycaster();
  ray.setFromCamera(ndc, this.camera);
  var overlays = [], viewer = this;
  Object.keys(this.overlays).forEach(function (k) { overlays = overlays.concat(viewer.overlays[k].pickables()); });
  var shape = ray.intersectObjects(overlays, false)[0];
  var best = null;
  ['change', 'map'].forEach(function (name) {
    if (!viewer.sets[name]) return;
    viewer.sets[name].objects().forEach(function (object) {
      object.traverse(function (o) {
        if (!o.isPoints || !o.visible) return;
        // A cell is drawn as a square of its size facing the camera: a ray through any of its
        // pixels passes within half a diagonal of its centre.
        ray.params.Points.threshold = o.userData.cells.cellM * 0.75;
        var hit = ray.intersectObject(o, false)[0];
        if (hit && (!best || hit.distance < best.distance - 1e-6)) best = hit;
      });
    });
  });
  // A shape wins unless a voxel stands clearly in front of it.
  var record = shape && (!best || shape.distance <= best.distance + 1.0)
    ? shape.object.userData.record : best ? this.cellRecord(best.object, best.index) : null;
  window.strataViewer.lastRecord = record;
  window.strataViewer.picks = (window.strataViewer.picks || 0) + 1;
  if (record) this.ui.showRecord(record);
  if (record && record.kind === 'voxel' && !strata.isStatic()) this.voxelRecord(record);
  return record;
};

strata.Viewer.prototype.cellRecord = function (points, k) {
  var cells = points.userData.cells, i = points.userData.index[k], m = this.manifest;
  var n = 1 << cells.lod, lo = [], hi = [], center = [];
  for (var a = 0; a < 3; a++) {
    var cell = Math.round(cells.origin[a] / cells.cellM) + cells.xyz[3 * i + a];
    lo.push(cell * n);
    hi.push(cell * n + n - 1);
    center.push((cell + 0.5) * cells.cellM);
  }
  var F = strata.FLAGS, f = cells.flags[i];
  var record = { kind: points.userData.kind === 'change' ? 'changed voxels' : cells.lod ? 'cell' : 'voxel',
                 lod: cells.lod, voxels: [lo, hi], center: center,
                 class: (m.legend[cells.label[i]] || m.legend[0]).name,
                 flags: Object.keys(F).filter(function (name) { return f & F[name]; }) };
  if (cells.session[i] !== strata.NONE) record.first_seen_by_session = cells.session[i];
  if (cells.slant[i] !== strata.NONE) record.slant_deg = cells.slant[i] / 2;
  var object = cells.object[i];
  if (f & F.wall) record.wall = m.walls.find(function (w) { return w.wall_id === object; }) || null;
  if (f & F.cleared) record.vehicle = m.vehicles.find(function (v) { return v.vehicle_id === object; }) || null;
  if (record.kind === 'changed voxels' && this.changeReport) {
    record.object = (this.changeReport.objects || []).find(function (o) {
      return [0, 1, 2].every(function (a) { return center[a] >= o.bbox_min[a] - 1e-6 && center[a] <= o.bbox_max[a] + 1e-6; });
    }) || null;
  }
  return record;
};

// The server's record of one voxel: every grid's value there and the rows it belongs to.
strata.Viewer.prototype.voxelRecord = function (cell) {
  var viewer = this, v = cell.voxels[0];
  window.strataViewer.recordPending = true;
  strata.load('/api/voxel/' + this.shown.commit + '/' + v[0] + '/' + v[1] + '/' + v[2], false)
    .then(function (record) {
      if (window.strataViewer.lastRecord !== cell) return;
      window.strataViewer.lastRecord = record;
      viewer.ui.showRecord(record);
    }).catch(function (error) { console.warn(String(error)); })
    .then(function () { window.strataViewer.recordPending = false; });
};
