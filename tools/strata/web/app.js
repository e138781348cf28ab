// strata view: the viewer. State lives in the URL (#camera=...&color=...&session=...), so a
// view can be shared and a test can open exactly the view it checks.
'use strict';
var strata = window.strata || (window.strata = {});

// What tests and benchmarks read over the DevTools protocol.
window.strataViewer = { ready: false, idle: false, firstPictureMs: null, errors: [] };
window.addEventListener('error', function (e) { window.strataViewer.errors.push(String(e.message)); });

strata.Viewer = function (manifest) {
  this.manifest = manifest;
  this.voxelM = manifest.map.voxel_size;
  this.state = strata.parseHash(location.hash, manifest);
  this.canvas = document.getElementById('view');
  this.renderer = new THREE.WebGLRenderer({ canvas: this.canvas, antialias: false });
  this.renderer.setPixelRatio(1);
  this.renderer.setClearColor(0x15181c);
  this.scene = new THREE.Scene();
  this.camera = new THREE.PerspectiveCamera(50, 1, 0.1, 20000);
  this.camera.up.set(0, 0, 1);
  this.controls = new THREE.OrbitControls(this.camera, this.canvas);
  this.controls.screenSpacePanning = true;
  this.groups = {};
  var viewer = this;
  ['map', 'change', 'free'].forEach(function (name) {
    viewer.groups[name] = new THREE.Group();
    viewer.scene.add(viewer.groups[name]);
  });
  this.overlays = { walls: new strata.Overlay(this.scene), vehicles: new strata.Overlay(this.scene),
                    changes: new strata.Overlay(this.scene) };
  this.sets = {};
  this.bounds = this.snapshotBounds(manifest.snapshots[0]);
  this.placeCamera();
  this.ui = new strata.Ui(this);
  this.controls.addEventListener('change', function () { viewer.dirty = true; viewer.moved = true; });
  window.addEventListener('resize', function () { viewer.resize(); });
  strata.installPicking(this);
  this.resize();
  this.apply();
  window.strataViewer.readyMs = performance.now();
  window.strataViewer.ready = true;
  window.strataViewer.viewer = this;
  this.loop();
};

strata.Viewer.prototype.snapshot = function () {
  var id = this.state.session;
  return this.manifest.snapshots.find(function (s) { return s.as_of_session === id; }) ||
         this.manifest.snapshots[0];
};

strata.Viewer.prototype.snapshotBounds = function (snapshot) {
  var box = new THREE.Box3();
  snapshot.tiles.forEach(function (t) {
    if (t.voxels) box.union(new THREE.Box3(new THREE.Vector3().fromArray(t.min),
                                           new THREE.Vector3().fromArray(t.max)));
  });
  if (box.isEmpty()) box.set(new THREE.Vector3(-10, -10, -1), new THREE.Vector3(10, 10, 1));
  return box;
};

// Looks at the whole map from the south, 40 degrees up, unless the URL says otherwise.
strata.Viewer.prototype.placeCamera = function () {
  var c = this.state.camera;
  if (c) {
    this.camera.position.set(c[0], c[1], c[2]);
    this.controls.target.set(c[3], c[4], c[5]);
  } else {
    var center = this.bounds.getCenter(new THREE.Vector3());
    var radius = this.bounds.getSize(new THREE.Vector3()).length() / 2;
    var d = 0.9 * radius / Math.sin(this.camera.fov * Math.PI / 360);
    var up = 40 * Math.PI / 180;
    this.camera.position.copy(center).add(
      new THREE.Vector3(0, -Math.cos(up), Math.sin(up)).multiplyScalar(d));
    this.controls.target.copy(center);
  }
  this.controls.update();
};

strata.Viewer.prototype.resize = function () {
  var w = this.canvas.clientWidth, h = this.canvas.clientHeight;
  this.renderer.setSize(w, h, false);
  this.camera.aspect = w / h;
  this.camera.updateProjectionMatrix();
  this.dirty = this.moved = true;
};

// Pixels per metre at distance 1: a cell of size s at depth d covers s * scale / d pixels.
strata.Viewer.prototype.pixelScale = function () {
  return this.canvas.clientHeight / (2 * Math.tan(this.camera.fov * Math.PI / 360));
};

strata.Viewer.prototype.set = function (change) {
  window.strataViewer.idle = false;  // until the new state is drawn
  Object.assign(this.state, change);
  this.apply();
};

strata.Viewer.prototype.sessionColor = function (id) {
  var i = this.manifest.sessions.findIndex(function (s) { return s.id === id; });
  return i < 0 ? strata.CONTEXT : strata.SESSION_COLORS[i % strata.SESSION_COLORS.length];
};

// The colour of cell i of a map tile under the current colour mode.
strata.Viewer.prototype.colorFunction = function (context) {
  var viewer = this, mode = this.state.color, legend = this.manifest.legend;
  var z0 = this.bounds.min.z, dz = Math.max(0.1, this.bounds.max.z - z0);
  var marked = this.state.layers.vehicles;
  return function (cells, i, out) {
    var f = cells.flags[i];
    if (marked && (f & strata.FLAGS.refilled)) return strata.copy(strata.REFILLED, out);
    if (context) {  // under a diff: the classes faded to grey, so changes stand out
      var c = (legend[cells.label[i]] || legend[0]).color, g = strata.CONTEXT;
      for (var k = 0; k < 3; k++) out[k] = Math.round(0.3 * c[k] + 0.7 * g[k]);
      return out;
    }
    if (mode === 'height') {
      return strata.ramp((cells.origin[2] + (cells.xyz[3 * i + 2] + 0.5) * cells.cellM - z0) / dz, out);
    }
    if (mode === 'session') return strata.copy(viewer.sessionColor(cells.session[i]), out);
    if (mode === 'slant') {
      var s = cells.slant[i];
      return s === strata.NONE ? strata.copy(strata.CONTEXT, out) : strata.slantColor(s / 2, out);
    }
    return strata.copy((legend[cells.label[i]] || legend[0]).color, out);
  };
};

strata.copy = function (rgb, out) { out[0] = rgb[0]; out[1] = rgb[1]; out[2] = rgb[2]; return out; };

strata.Viewer.prototype.loop = function () {
  var viewer = this;
  requestAnimationFrame(function () { viewer.loop(); });
  var now = performance.now();
  if (this.moved && (!this.lastPlan || now - this.lastPlan > 150)) {
    this.moved = false;
    this.lastPlan = now;
    this.plan();
    strata.writeHash(this);
  }
  if (!this.dirty) return;
  this.dirty = false;
  this.renderer.render(this.scene, this.camera);
  var cells = this.cellsDrawn();
  if (cells > 0 && window.strataViewer.firstPictureMs === null) {
    window.strataViewer.firstPictureMs = performance.now();
  }
  this.report(cells);
};

strata.Viewer.prototype.cellsDrawn = function () {
  var sets = this.sets;
  return Object.keys(sets).reduce(function (n, k) { return n + sets[k].cells; }, 0);
};

strata.Viewer.prototype.plan = function () {
  var scale = this.pixelScale(), camera = this.camera, sets = this.sets;
  camera.updateMatrixWorld();
  this.scene.traverse(function (o) {
    if (o.material && o.material.uniforms && o.material.uniforms.scale) o.material.uniforms.scale.value = scale;
  });
  Object.keys(sets).forEach(function (k) { sets[k].plan(camera, scale); sets[k].request(); });
  this.dirty = true;
};

strata.Viewer.prototype.report = function (cells) {
  var sets = this.sets, keys = Object.keys(sets);
  var settled = keys.every(function (k) { return sets[k].settled(); });
  var loading = keys.reduce(function (n, k) { return n + sets[k].inFlight; }, 0);
  var total = keys.reduce(function (n, k) { return n + sets[k].entries.length; }, 0);
  var requested = keys.reduce(function (n, k) { return n + sets[k].requested(); }, 0);
  Object.assign(window.strataViewer, { idle: settled && !this.pendingChange, cells: cells,
                                       tilesRequested: requested, tilesTotal: total });
  this.ui.status(cells.toLocaleString() + ' cells drawn' + (loading ? ', loading ' + loading + ' tiles' : ''));
};

window.addEventListener('load', function () {
  window.strataViewer.loadMs = performance.now();
  strata.load('/api/map', false).then(function (manifest) {
    window.strataViewer.manifestMs = performance.now();
    document.title = 'strata view: ' + manifest.map.name;
    document.getElementById('title').textContent = manifest.map.name;
    new strata.Viewer(manifest);
  }).catch(function (error) {
    document.getElementById('status').textContent = String(error);
    window.strataViewer.errors.push(String(error));
  });
});
