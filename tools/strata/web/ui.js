// strata view: the panel (colour, layers, change sets, legend), the session timeline and the
// record of what was clicked. Reads and changes the viewer's state; never draws.
'use strict';
var strata = window.strata || (window.strata = {});

function el(id) { return document.getElementById(id); }

function rgbCss(c) { return 'rgb(' + c[0] + ',' + c[1] + ',' + c[2] + ')'; }

function swatch(color, text) {
  return '<div><span class="swatch" style="background:' + rgbCss(color) + '"></span>' +
         text + '</div>';
}

strata.Ui = function (viewer) {
  this.viewer = viewer;
  var ui = this, state = viewer.state;
  el('color').value = state.color;
  el('color').onchange = function () { viewer.set({ color: this.value }); };
  ['walls', 'vehicles', 'cleared'].forEach(function (name) {
    el(name).checked = state.layers[name];
    el(name).onchange = function () {
      var layers = Object.assign({}, viewer.state.layers);
      layers[name] = this.checked;
      viewer.set({ layers: layers });
    };
  });
  el('free').checked = state.free !== null;
  el('free').disabled = strata.isStatic();
  el('free').onchange = el('free-z').oninput = function () {
    viewer.set({ free: el('free').checked ? ui.freeHeight() : null });
  };
  var sets = el('changeset');
  viewer.manifest.change_sets.forEach(function (s) {
    var option = document.createElement('option');
    option.value = s.id;
    var r = s.report || {};
    option.textContent = '#' + s.id + ' ' + s.from + ' → ' + s.to + ' (+' + r.added_voxels +
                         ' / −' + r.removed_voxels + ')';
    sets.appendChild(option);
  });
  sets.value = state.changeset || '';
  sets.onchange = function () {
    viewer.set({ changeset: this.value ? Number(this.value) : null, diff: null });
  };
  el('record-close').onclick = function () { el('record').hidden = true; };
  this.timeline();
  this.update();
};

strata.Ui.prototype.freeHeight = function () {
  var b = this.viewer.bounds, t = Number(el('free-z').value);
  return b.min.z + t * (b.max.z - b.min.z);
};

// One button per session of the history; removed ones are shown but cannot be picked.
strata.Ui.prototype.timeline = function () {
  var viewer = this.viewer, bar = el('timeline');
  bar.innerHTML = '';
  var first = viewer.manifest.snapshots[0];
  var newest = document.createElement('button');
  newest.textContent = first.as_of_session ? 'as of session ' + first.as_of_session : 'newest';
  newest.dataset.session = 0;
  newest.title = 'commit ' + first.commit;
  bar.appendChild(newest);
  viewer.manifest.sessions.forEach(function (s) {
    var b = document.createElement('button');
    b.textContent = '#' + s.id + ' ' + s.name;
    b.dataset.session = s.id;
    b.title = (s.start_utc || '') + ' · ' + s.scans + ' scans · ' + s.source;
    b.disabled = first.sessions.indexOf(s.id) < 0;
    if (b.disabled) b.title += ' (removed)';
    bar.appendChild(b);
  });
  bar.onclick = function (e) {
    var b = e.target.closest('button');
    if (!b || b.disabled) return;
    var id = Number(b.dataset.session), current = viewer.state.session;
    if (e.shiftKey && id && current && id !== current) {
      viewer.set({ diff: [Math.min(id, current), Math.max(id, current)], changeset: null });
    } else {
      viewer.set({ session: id, diff: null, changeset: null });
    }
  };
  var hint = document.createElement('span');
  hint.className = 'hint';
  hint.textContent = 'click: the map as of a session · shift-click another: what changed';
  bar.appendChild(hint);
};

strata.Ui.prototype.update = function () {
  var state = this.viewer.state;
  Array.prototype.forEach.call(el('timeline').querySelectorAll('button'), function (b) {
    var id = Number(b.dataset.session);
    b.classList.toggle('selected', !state.diff && id === (state.session || 0));
    b.classList.toggle('compared', !!state.diff && state.diff.indexOf(id) >= 0);
  });
  el('changeset').value = state.changeset || '';
  el('panel').style.display = el('timeline').style.display = state.ui ? '' : 'none';
  this.legend();
};

strata.Ui.prototype.legend = function () {
  var v = this.viewer, state = v.state, html = '';
  if (state.color === 'class') {
    v.manifest.legend.forEach(function (c) { html += swatch(c.color, c.name); });
  } else if (state.color === 'height') {
    html += swatch(strata.ramp(0, []), v.bounds.min.z.toFixed(1) + ' m') +
            swatch(strata.ramp(1, []), v.bounds.max.z.toFixed(1) + ' m');
  } else if (state.color === 'session') {
    v.manifest.sessions.forEach(function (s) {
      html += swatch(v.sessionColor(s.id), '#' + s.id + ' ' + s.name);
    });
  } else {
    html += swatch(strata.slantColor(90, []), 'vertical') +
            swatch(strata.slantColor(90 - strata.SLANT_RANGE_DEG, []),
                   '≥ ' + strata.SLANT_RANGE_DEG + '° lean') + swatch(strata.CONTEXT, 'not a wall');
  }
  if (state.diff || state.changeset) {
    html += '<br>' + swatch(strata.ADDED, 'added') + swatch(strata.REMOVED, 'removed');
  }
  if (state.layers.vehicles) {
    html += '<br>' + swatch(strata.VEHICLE_BOX, 'vehicle box') + swatch(strata.REFILLED, 'refilled');
  }
  el('legend').innerHTML = html;
};

strata.Ui.prototype.status = function (text) { el('status').textContent = text; };
strata.Ui.prototype.describe = function (text) { el('snapshot').textContent = text; };

strata.Ui.prototype.showRecord = function (record) {
  el('record').querySelector('pre').textContent = JSON.stringify(record, null, 2);
  el('record').hidden = false;
};
