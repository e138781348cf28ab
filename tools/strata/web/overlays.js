// strata view: what is drawn besides voxels: walls as their fitted planes with slant labels,
// vehicle boxes, the boxes of changed objects. Each carries its catalog row for a click.
'use strict';
var strata = window.strata || (window.strata = {});

function label(text, color) {
  var canvas = document.createElement('canvas');
  canvas.width = 256;
  canvas.height = 64;
  var g = canvas.getContext('2d');
  g.fillStyle = 'rgba(20, 22, 26, 0.8)';
  g.fillRect(0, 0, 256, 64);
  g.font = 'bold 40px sans-serif';
  g.fillStyle = color;
  g.textAlign = 'center';
  g.textBaseline = 'middle';
  g.fillText(text, 128, 34);
  var sprite = new THREE.Sprite(new THREE.SpriteMaterial({
    map: new THREE.CanvasTexture(canvas), depthTest: false, sizeAttenuation: false,
  }));
  sprite.scale.set(0.1, 0.025, 1);  // a fixed size on screen, readable at any distance
  sprite.renderOrder = 10;
  return sprite;
}

function hex(rgb) {
  return (rgb[0] << 16) | (rgb[1] << 8) | rgb[2];
}

// A wall's fitted plane: a rectangle of its length and height about its centre, in the plane
// through the centre with the wall's normal.
strata.wallObject = function (wall) {
  var n = new THREE.Vector3().fromArray(wall.normal).normalize();
  var along = new THREE.Vector3(0, 0, 1).cross(n);
  if (along.lengthSq() < 1e-9) along.set(1, 0, 0);
  along.normalize();
  var up = new THREE.Vector3().crossVectors(n, along).normalize();
  if (up.z < 0) { up.negate(); along.negate(); }
  var color = hex(strata.slantColor(wall.slant_deg, [0, 0, 0]));
  var plane = new THREE.Mesh(
    new THREE.PlaneBufferGeometry(Math.max(wall.length_m, 0.5), Math.max(wall.height_m, 0.5)),
    new THREE.MeshBasicMaterial({
      color: color, transparent: true, opacity: 0.25, side: THREE.DoubleSide, depthWrite: false,
    }));
  plane.matrixAutoUpdate = false;
  plane.matrix.makeBasis(along, up, n).setPosition(new THREE.Vector3().fromArray(wall.center));
  var group = new THREE.Group();
  group.add(plane);
  group.add(new THREE.LineSegments(new THREE.EdgesGeometry(plane.geometry),
                                   new THREE.LineBasicMaterial({ color: color })));
  group.children[1].matrixAutoUpdate = false;
  group.children[1].matrix.copy(plane.matrix);
  var tag = label(wall.slant_deg.toFixed(1) + '°', '#' + ('00000' + color.toString(16)).slice(-6));
  tag.position.fromArray(wall.center).addScaledVector(up, wall.height_m / 2 + 0.6);
  group.add(tag);
  plane.userData.record = Object.assign({ kind: 'wall' }, wall);
  return group;
};

// An upright box turned by yaw about z: its edges, and an undrawn fill that a click can hit
// (a drawn one would tint what is inside, such as the refilled ground under a cleared car).
function box(center, size, yawDeg, rgb, record) {
  var geometry = new THREE.BoxBufferGeometry(size[0], size[1], size[2]);
  var group = new THREE.Group();
  var fill = new THREE.Mesh(geometry, new THREE.MeshBasicMaterial({ visible: false }));
  fill.userData.record = record;
  group.add(fill);
  group.add(new THREE.LineSegments(new THREE.EdgesGeometry(geometry),
                                   new THREE.LineBasicMaterial({ color: hex(rgb) })));
  group.position.fromArray(center);
  group.rotation.z = yawDeg * Math.PI / 180;
  return group;
}

strata.VEHICLE_BOX = [255, 60, 220];
strata.vehicleObject = function (v) {
  return box(v.center, v.size, v.yaw_deg, strata.VEHICLE_BOX, Object.assign({ kind: 'vehicle' }, v));
};

strata.changeObject = function (o, sides) {
  var b = o.oriented_box;
  return box(b.center, b.size, b.yaw_deg, o.kind === 'added' ? strata.ADDED : strata.REMOVED,
             Object.assign({ kind: 'change', from: sides.from, to: sides.to }, o));
};

// The catalog rows a group of overlays shows, rebuilt when the rows change.
strata.Overlay = function (scene) {
  this.group = new THREE.Group();
  scene.add(this.group);
};
strata.Overlay.prototype.show = function (objects) {
  while (this.group.children.length) this.group.remove(this.group.children[0]);
  var group = this.group;
  objects.forEach(function (o) { group.add(o); });
};
strata.Overlay.prototype.pickables = function () {
  var out = [];
  if (!this.group.visible) return out;
  this.group.traverse(function (o) { if (o.userData && o.userData.record) out.push(o); });
  return out;
};
