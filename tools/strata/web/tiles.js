// strata view: loading answers (from the server, or from script files in a static export),
// decoding tiles (docs/viewer.md, "Tile format") and drawing their cells as points.
'use strict';
var strata = window.strata || (window.strata = {});

// ---- transport -----------------------------------------------------------------------------
// A static export holds every answer as data/<path with / as _>.js calling strataPayload(path,
// data): pages opened from file:// may load scripts but not fetch files.
strata.payloads = {};
strata.waiting = {};
window.strataPayload = function (path, data) {
  strata.payloads[path] = data;
  (strata.waiting[path] || []).forEach(function (w) { w.resolve(data); });
  delete strata.waiting[path];
};

strata.isStatic = function () { return '/api/map' in strata.payloads; };

function base64ToBuffer(text) {
  var raw = atob(text), bytes = new Uint8Array(raw.length);
  for (var i = 0; i < raw.length; i++) bytes[i] = raw.charCodeAt(i);
  return bytes.buffer;
}

// Resolves to parsed JSON (binary = false) or an ArrayBuffer (binary = true).
strata.load = function (path, binary) {
  if (!strata.isStatic()) {
    return fetch(path).then(function (r) {
      if (!r.ok) {
        return r.json().then(function (e) { throw new Error(path + ': ' + e.error); });
      }
      return binary ? r.arrayBuffer() : r.json();
    });
  }
  var convert = function (d) { return binary ? base64ToBuffer(d) : d; };
  if (path in strata.payloads) return Promise.resolve(convert(strata.payloads[path]));
  return new Promise(function (resolve, reject) {
    var first = !(path in strata.waiting);
    (strata.waiting[path] = strata.waiting[path] || []).push({ resolve: resolve });
    if (!first) return;
    var script = document.createElement('script');
    script.src = 'data/' + path.slice(1).split('/').join('_') + '.js';
    script.onerror = function () {
      delete strata.waiting[path];
      reject(new Error(path + ': not in this static export'));
    };
    document.head.appendChild(script);
  }).then(convert);
};

// ---- tile format ---------------------------------------------------------------------------
strata.FLAGS = { refilled: 1, cleared: 2, wall: 4, free: 8, added: 16, removed: 32 };
strata.NONE = 255;

strata.decodeCells = function (buffer) {
  var view = new DataView(buffer);
  var magic = String.fromCharCode(view.getUint8(0), view.getUint8(1), view.getUint8(2),
                                  view.getUint8(3));
  if (magic !== 'STV1') throw new Error('not a strata tile');
  var n = view.getUint32(4, true);
  var cells = {
    count: n, lod: view.getInt32(8, true), cellM: view.getFloat32(12, true),
    origin: [view.getFloat32(16, true), view.getFloat32(20, true), view.getFloat32(24, true)],
  };
  cells.xyz = new Int16Array(buffer, 32, 3 * n);
  var at = 32 + 6 * n;
  ['label', 'session', 'slant', 'flags'].forEach(function (name) {
    cells[name] = new Uint8Array(buffer, at, n);
    at += n;
  });
  cells.object = new Uint16Array(buffer, at, n);
  return cells;
};

// ---- drawing -------------------------------------------------------------------------------
// Each cell is a square point as large on screen as the cell would be (flat colours, so a
// screenshot shows exactly the colour of a class).
var VERTEX = [
  'attribute vec3 rgb;',
  'uniform float scale;', 'uniform float cellSize;', 'uniform float depthBias;',
  'varying vec3 vColor;',
  'void main() {',
  '  vec4 mv = modelViewMatrix * vec4(position, 1.0);',
  '  gl_Position = projectionMatrix * mv;',
  '  gl_Position.z -= depthBias * gl_Position.w;',
  '  gl_PointSize = max(1.0, cellSize * scale / -mv.z);',
  '  vColor = rgb;',
  '}'].join('\n');
var FRAGMENT = [
  'uniform float opacity;', 'varying vec3 vColor;',
  'void main() { gl_FragColor = vec4(vColor, opacity); }'].join('\n');

strata.pointMaterial = function (cellM, opacity, depthBias) {
  return new THREE.ShaderMaterial({
    uniforms: {
      scale: { value: 1 }, cellSize: { value: cellM }, opacity: { value: opacity },
      depthBias: { value: depthBias || 0 },
    },
    vertexShader: VERTEX, fragmentShader: FRAGMENT,
    transparent: opacity < 1, depthWrite: opacity >= 1,
  });
};

// Points for the cells passing `keep(i)`; `colorOf(cells, i, out)` writes 3 bytes.
strata.buildPoints = function (cells, keep, colorOf, opacity, depthBias) {
  var index = [];
  for (var i = 0; i < cells.count; i++) if (keep(i)) index.push(i);
  var position = new Float32Array(3 * index.length), rgb = new Uint8Array(3 * index.length);
  var c = cells.cellM, o = cells.origin, x = cells.xyz;
  for (var k = 0; k < index.length; k++) {
    var j = index[k];
    position[3 * k] = o[0] + (x[3 * j] + 0.5) * c;
    position[3 * k + 1] = o[1] + (x[3 * j + 1] + 0.5) * c;
    position[3 * k + 2] = o[2] + (x[3 * j + 2] + 0.5) * c;
  }
  var geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(position, 3));
  geometry.setAttribute('rgb', new THREE.BufferAttribute(rgb, 3, true));
  geometry.computeBoundingSphere();
  var points = new THREE.Points(geometry, strata.pointMaterial(c, opacity, depthBias));
  points.userData = { cells: cells, index: index };
  strata.recolor(points, colorOf);
  return points;
};

strata.recolor = function (points, colorOf) {
  var rgb = points.geometry.getAttribute('rgb'), index = points.userData.index;
  var out = [0, 0, 0];
  for (var k = 0; k < index.length; k++) {
    colorOf(points.userData.cells, index[k], out);
    rgb.array[3 * k] = out[0];
    rgb.array[3 * k + 1] = out[1];
    rgb.array[3 * k + 2] = out[2];
  }
  rgb.needsUpdate = true;
};

// ---- colours -------------------------------------------------------------------------------
// A blue -> cyan -> green -> yellow -> red ramp for t in [0, 1].
strata.ramp = function (t, out) {
  t = Math.min(1, Math.max(0, t));
  var stops = [[40, 60, 220], [0, 190, 230], [40, 200, 70], [240, 220, 40], [230, 40, 30]];
  var f = t * (stops.length - 1), i = Math.min(stops.length - 2, Math.floor(f)), u = f - i;
  for (var k = 0; k < 3; k++) out[k] = Math.round(stops[i][k] * (1 - u) + stops[i + 1][k] * u);
  return out;
};

// How far a wall leans from vertical, as a colour: 0 degrees blue, 6 or more red.
strata.SLANT_RANGE_DEG = 6;
strata.slantColor = function (slantDeg, out) {
  return strata.ramp(Math.abs(90 - slantDeg) / strata.SLANT_RANGE_DEG, out);
};

strata.SESSION_COLORS = [[230, 120, 40], [60, 150, 240], [120, 200, 60], [200, 80, 200],
                         [240, 200, 40], [60, 200, 190], [240, 90, 100], [150, 130, 240]];
strata.ADDED = [0, 200, 60];
strata.REMOVED = [230, 30, 30];
strata.REFILLED = [255, 240, 0];
strata.CONTEXT = [105, 108, 115];
