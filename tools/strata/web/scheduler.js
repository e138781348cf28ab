// strata view: which tiles to ask for, at which level of detail. Only tiles in the view are
// requested; a tile's level follows how large one voxel of it appears on screen (fine near,
// coarse far); a tile with nothing drawn yet gets its coarsest level first, so a first picture
// comes fast whatever the map's size.
'use strict';
var strata = window.strata || (window.strata = {});

strata.TARGET_PIXELS = 1.5;  // a cell should cover at least this many pixels
strata.MAX_IN_FLIGHT = 6;

// tiles: [{key, min: [x,y,z], max: [x,y,z], path: function (lod) -> string}]
// build: function (cells, tile) -> THREE.Object3D drawn for the tile
strata.TileSet = function (group, tiles, maxLod, voxelM, build) {
  this.group = group;
  this.maxLod = maxLod;
  this.voxelM = voxelM;
  this.build = build;
  this.entries = tiles.map(function (t) {
    return {
      tile: t, wanted: -1, shownLod: -1, object: null, pending: false, failed: false,
      box: new THREE.Box3(new THREE.Vector3().fromArray(t.min), new THREE.Vector3().fromArray(t.max)),
    };
  });
  this.inFlight = 0;
  this.cells = 0;
  this.planned = false;  // no camera has chosen levels yet: not settled
  this.onchange = function () {};
};

strata.TileSet.prototype.dispose = function () {
  var group = this.group;
  this.entries.forEach(function (e) { if (e.object) strata.disposeObject(group, e.object); });
  this.entries = [];
};

strata.disposeObject = function (parent, object) {
  parent.remove(object);
  object.traverse(function (o) {
    if (o.geometry) o.geometry.dispose();
    if (o.material) o.material.dispose();
  });
};

// Picks each tile's level for this camera; `scale` is pixels per metre at distance 1.
strata.TileSet.prototype.plan = function (camera, scale) {
  var frustum = new THREE.Frustum().setFromMatrix(
    new THREE.Matrix4().multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse));
  var set = this;
  this.planned = true;
  this.entries.forEach(function (e) {
    if (!frustum.intersectsBox(e.box)) { e.wanted = -1; return; }
    var d = Math.max(e.box.distanceToPoint(camera.position), 1e-3);
    var pixels = set.voxelM * scale / d;
    var lod = Math.ceil(Math.log2(strata.TARGET_PIXELS / pixels));
    e.wanted = Math.min(set.maxLod, Math.max(0, lod));
    e.distance = d;
  });
};

// Starts requests for the tiles whose drawn level is not the wanted one, nearest first, those
// with nothing drawn before all others.
strata.TileSet.prototype.request = function () {
  var todo = this.entries.filter(function (e) {
    return e.wanted >= 0 && !e.pending && !e.failed && e.shownLod !== e.wanted;
  });
  todo.sort(function (a, b) {
    return ((a.object ? 1 : 0) - (b.object ? 1 : 0)) || a.distance - b.distance;
  });
  for (var i = 0; i < todo.length && this.inFlight < strata.MAX_IN_FLIGHT; i++) {
    var e = todo[i];
    this.fetch(e, e.object ? e.wanted : this.maxLod);
  }
};

strata.TileSet.prototype.fetch = function (e, lod) {
  var set = this;
  e.pending = true;
  this.inFlight++;
  strata.load(e.tile.path(lod), true).then(function (buffer) {
    if (set.entries.indexOf(e) < 0) return;  // disposed meanwhile
    var object = set.build(strata.decodeCells(buffer), e.tile);
    if (e.object) { set.cells -= e.object.userData.cellCount; strata.disposeObject(set.group, e.object); }
    e.object = object;
    e.shownLod = lod;
    set.cells += object.userData.cellCount;
    set.group.add(object);
  }).catch(function (error) {
    e.failed = true;
    console.warn(String(error));
  }).then(function () {
    e.pending = false;
    set.inFlight--;
    set.onchange();
  });
};

// True when every tile in view is drawn at its wanted level and nothing is loading.
strata.TileSet.prototype.settled = function () {
  return this.planned && this.inFlight === 0 && this.entries.every(function (e) {
    return e.wanted < 0 || e.failed || e.shownLod === e.wanted;
  });
};

strata.TileSet.prototype.objects = function () {
  return this.entries.filter(function (e) { return e.object; }).map(function (e) { return e.object; });
};

strata.TileSet.prototype.requested = function () {
  return this.entries.filter(function (e) { return e.object || e.pending; }).length;
};
