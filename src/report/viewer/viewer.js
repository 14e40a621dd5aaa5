// --- The linked plots (issue 27, item 3) --------------------------------------------------------
// Small canvas 2-D plots of the run's series (D.plots, D.series: float32, one row per frame, the
// frames' times), the phases shaded as on the time line, a cursor at the slider's frame; a click
// or a drag on a plot moves the slider (an 'input' event on it, as a user's). Each plot is drawn
// once per size into a canvas of its own, and the cursor over a copy of it. Many series (the
// joints of a humanoid): coloured from a palette of 10, named in the legend up to 8, else the
// one nearest the pointer is named (and drawn thicker) on hover.
function kdlSpacePlots(K, D, times, slider, phaseColours) {
 'use strict';
 var box = document.getElementById('plots'), n = times.length;
 if (!D.plots || !D.plots.length || !D.series || !box) return null;
 var bytes = atob(D.series), raw = new Uint8Array(bytes.length);
 for (var b = 0; b < bytes.length; ++b) raw[b] = bytes.charCodeAt(b);
 var values = new Float32Array(raw.buffer), stride = D.seriesStride;
 var PALETTE = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2', '#7f7f7f', '#bcbd22', '#17becf'];
 var CURSOR = '#ff00ff', LEFT = 52, RIGHT = 8, TOP = 16, BOTTOM = 14;
 var t0 = times[0], span = Math.max(times[n - 1] - t0, 1e-12), current = 0;
 document.body.classList.add('with-plots');
 box.style.gridTemplateColumns = 'repeat(' + Math.ceil(D.plots.length / 2) + ', 1fr)';
 function value(p, s, k) { return values[k * stride + p.column + s]; }
 var plots = D.plots.map(function (p) {
   var cell = document.createElement('div'), canvas = document.createElement('canvas');
   cell.appendChild(canvas);
   box.appendChild(cell);
   canvas.title = p.label;
   var lo = Infinity, hi = -Infinity;
   for (var k = 0; k < n; ++k)
     for (var s = 0; s < p.series.length; ++s) {
       var v = value(p, s, k);
       if (isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
     }
   if (!(hi >= lo)) { lo = -1; hi = 1; }
   if (hi - lo < 1e-12 * Math.max(1, Math.abs(hi))) { var pad = Math.max(Math.abs(hi) * 0.1, 1e-9); lo -= pad; hi += pad; }
   else { var margin = 0.05 * (hi - lo); lo -= margin; hi += margin; }  // a flat line off the frame
   return { spec: p, canvas: canvas, back: document.createElement('canvas'), lo: lo, hi: hi, hover: -1 };
 });
 function xOf(q, t) { return LEFT + (t - t0) / span * (q.back.width - LEFT - RIGHT); }
 function yOf(q, v) { return TOP + (q.hi - v) / (q.hi - q.lo) * (q.back.height - TOP - BOTTOM); }
 function drawBack(q) {
   var c = q.back.getContext('2d'), w = q.back.width, h = q.back.height, p = q.spec;
   c.fillStyle = '#fff'; c.fillRect(0, 0, w, h);
   for (var s0 = 0; s0 < n; ) {  // the phases
     var e = s0;
     while (e + 1 < n && D.phases[e + 1] === D.phases[s0]) ++e;
     c.globalAlpha = 0.12;
     c.fillStyle = phaseColours[D.phases[s0]] || '#999';
     var x0 = xOf(q, times[s0]), x1 = xOf(q, times[Math.min(e + 1, n - 1)]);
     c.fillRect(x0, TOP, Math.max(x1 - x0, 1), h - TOP - BOTTOM);
     c.globalAlpha = 1;
     s0 = e + 1;
   }
   c.strokeStyle = '#bbb'; c.lineWidth = 1;
   c.strokeRect(LEFT, TOP, w - LEFT - RIGHT, h - TOP - BOTTOM);
   if (q.lo < 0 && q.hi > 0) { c.beginPath(); c.moveTo(LEFT, yOf(q, 0)); c.lineTo(w - RIGHT, yOf(q, 0)); c.stroke(); }
   for (var s = 0; s < p.series.length; ++s) {
     c.strokeStyle = PALETTE[s % PALETTE.length];
     c.lineWidth = s === q.hover ? 2.5 : 1;
     c.beginPath();
     var up = false;
     for (var k = 0; k < n; ++k) {
       var v = value(p, s, k);
       if (!isFinite(v)) { up = false; continue; }
       if (up) c.lineTo(xOf(q, times[k]), yOf(q, v)); else c.moveTo(xOf(q, times[k]), yOf(q, v));
       up = true;
     }
     c.stroke();
   }
   c.fillStyle = '#222'; c.font = '10px sans-serif'; c.textBaseline = 'top';
   c.fillText(p.label, 4, 2);
   c.fillText(q.hi.toPrecision(3), 2, TOP);
   c.textBaseline = 'bottom';
   c.fillText(q.lo.toPrecision(3), 2, h - BOTTOM);
   c.fillText(t0.toFixed(2) + ' s', LEFT, h);
   c.textAlign = 'right';
   c.fillText(times[n - 1].toFixed(2) + ' s', w - RIGHT, h);
   c.textBaseline = 'top';
   var legend = p.series.length <= 8 ? null : p.series.length + ' series: hover for a name';
   if (q.hover >= 0) legend = p.series[q.hover] + ' = ' + value(p, q.hover, current).toPrecision(5);
   if (legend !== null) { c.fillStyle = '#222'; c.fillText(legend, w - RIGHT - 2, TOP + 2); }
   else
     for (var s2 = p.series.length - 1, x = w - RIGHT - 2; s2 >= 0; --s2) {
       c.fillStyle = PALETTE[s2 % PALETTE.length];
       c.fillText(p.series[s2], x, TOP + 2);
       x -= c.measureText(p.series[s2]).width + 8;
     }
   c.textAlign = 'left';
 }
 function drawCursor(q) {
   var c = q.canvas.getContext('2d'), x = Math.round(xOf(q, times[current])) + 0.5;
   c.drawImage(q.back, 0, 0);
   c.strokeStyle = CURSOR; c.lineWidth = 1;
   c.beginPath(); c.moveTo(x, TOP); c.lineTo(x, q.canvas.height - BOTTOM); c.stroke();
   q.cursorX = x - 0.5;
 }
 function resize() {
   plots.forEach(function (q) {
     var w = Math.max(q.canvas.clientWidth, 60), h = Math.max(q.canvas.clientHeight, 40);
     q.canvas.width = q.back.width = w; q.canvas.height = q.back.height = h;
     drawBack(q); drawCursor(q);
   });
 }
 // The frame nearest a time.
 function frameAt(t) {
   var lo = 0, hi = n - 1;
   while (hi - lo > 1) { var mid = (lo + hi) >> 1; if (times[mid] <= t) lo = mid; else hi = mid; }
   return Math.abs(times[hi] - t) < Math.abs(t - times[lo]) ? hi : lo;
 }
 function timeAtX(q, clientX) {
   var r = q.canvas.getBoundingClientRect(), x = (clientX - r.left) * q.canvas.width / Math.max(r.width, 1);
   return t0 + (x - LEFT) / (q.canvas.width - LEFT - RIGHT) * span;
 }
 var dragging = null;
 function moveTo(q, e) {
   slider.value = String(frameAt(timeAtX(q, e.clientX)));
   slider.dispatchEvent(new Event('input'));
 }
 plots.forEach(function (q) {
   q.canvas.addEventListener('mousedown', function (e) { dragging = q; moveTo(q, e); e.preventDefault(); });
   q.canvas.addEventListener('mousemove', function (e) {
     if (dragging === q) { moveTo(q, e); return; }
     var r = q.canvas.getBoundingClientRect(), y = (e.clientY - r.top) * q.canvas.height / Math.max(r.height, 1);
     var k = frameAt(timeAtX(q, e.clientX)), best = -1, d = 8;  // the series within 8 px of the pointer
     for (var s = 0; s < q.spec.series.length; ++s) {
       var v = value(q.spec, s, k);
       if (isFinite(v) && Math.abs(yOf(q, v) - y) < d) { d = Math.abs(yOf(q, v) - y); best = s; }
     }
     if (best !== q.hover) { q.hover = best; drawBack(q); drawCursor(q); }
   });
   q.canvas.addEventListener('mouseleave', function () { if (q.hover >= 0) { q.hover = -1; drawBack(q); drawCursor(q); } });
 });
 window.addEventListener('mouseup', function () { dragging = null; });
 window.addEventListener('resize', resize);
 function find(name) {
   for (var i = 0; i < plots.length; ++i) if (plots[i].spec.name === name) return plots[i];
   return null;
 }
 // The tests' hooks.
 K.plots = plots.map(function (q) { return { name: q.spec.name, label: q.spec.label, series: q.spec.series.slice(), samples: n }; });
 K.plotValue = function (name, series, k) {
   var q = find(name), s = q ? q.spec.series.indexOf(series) : -1;
   return s < 0 || k < 0 || k >= n ? null : value(q.spec, s, k);
 };
 // Where a time is on a plot, in the page's coordinates (for a mouse event), and the cursor drawn.
 K.plotPoint = function (name, t) {
   var q = find(name), r = q.canvas.getBoundingClientRect();
   return { x: r.left + xOf(q, t) * r.width / q.canvas.width, y: r.top + r.height / 2 };
 };
 K.plotCursor = function (name) { var q = find(name); return { frame: current, x: q.cursorX, time: times[current] }; };
 K.plotCanvas = function (name) { return find(name).canvas; };
 resize();
 return { cursor: function (k) { current = k; plots.forEach(drawCursor); } };
}
// --- end of the linked plots ---------------------------------------------------------------------
function kdlSpaceMain() {
 'use strict';
 var K = window.kdlSpace, D = window.KDL_DATA;
 var PHASE_COLOURS = ['#4c78a8', '#d62728', '#59a14f', '#9c9c9c', '#f28e2b'];
 function decode(text, Type) {
   var bytes = atob(text), raw = new Uint8Array(bytes.length);
   for (var i = 0; i < bytes.length; ++i) raw[i] = bytes.charCodeAt(i);
   return new Type(raw.buffer);
 }
 function colour(rgba) { return new THREE.Color(rgba[0], rgba[1], rgba[2]); }
 function material(rgba) {
   rgba = rgba || [0.55, 0.6, 0.7, 1];
   return new THREE.MeshPhongMaterial({ color: colour(rgba), transparent: rgba[3] < 1, opacity: rgba[3] });
 }
 function place(object, pose) {
   object.position.set(pose[0], pose[1], pose[2]);
   object.quaternion.set(pose[3], pose[4], pose[5], pose[6]);
 }
 // --- meshes (STL, COLLADA): each file of D.meshes parsed once by three's own loaders; a visual
 // is a clone sharing its geometry, in a group that carries the visual's origin and URDF scale.
 function meshMaterial(rgba) {  // both sides lit: a mesh's triangles need not all face out
   var m = material(rgba);
   m.side = THREE.DoubleSide;
   return m;
 }
 var meshSources = (D.meshes || []).map(function (m) {
   try {
     var bytes = decode(m.data, Uint8Array);
     if (m.format === 'stl') {
       // An STL's facet normals are often zeros (then the mesh is black): from its triangles.
       var g = new THREE.STLLoader().parse(bytes.buffer);
       g.computeVertexNormals();
       return new THREE.Mesh(g, meshMaterial(null));
     }
     // Whatever the file still names (a texture, another file) is never fetched: every URL the
     // loader asks for becomes an empty data: URL (the writer removed the DAE's images already).
     var offline = new THREE.LoadingManager();
     offline.setURLModifier(function () { return 'data:,'; });
     var dae = new THREE.ColladaLoader(offline).parse(new TextDecoder().decode(bytes), '');
     dae.scene.traverse(function (o) {  // a DAE without normals: from its triangles
       if (o.isMesh && o.geometry.isBufferGeometry && !o.geometry.attributes.normal) o.geometry.computeVertexNormals();
     });
     // <unit> is kept (the loader scales by it, as RViz does); <up_axis> is not: RViz ignores it,
     // so a mesh's coordinates are its link's, whatever the DAE says is up (three's loader turns
     // Z_UP into its own Y up, which this Z-up page must not).
     dae.scene.quaternion.set(0, 0, 0, 1);
     return dae.scene;
   } catch (e) {
     K.errors.push('the mesh ' + m.file + ' could not be read: ' + (e && e.message));
     return null;
   }
 });
 function meshVisual(v) {
   var group = new THREE.Group(), source = meshSources[v.mesh];
   if (source) {
     var object = source.clone();
     if (v.rgba) {  // the URDF's colour wins over a DAE's own materials
       var m = meshMaterial(v.rgba);
       object.traverse(function (o) { if (o.isMesh) o.material = m; });
     }
     group.add(object);
   }
   place(group, v.origin);
   group.scale.set(v.scale[0], v.scale[1], v.scale[2]);
   return group;
 }
 // --- end of meshes
 function visualMesh(v) {
   if (v.shape === 'mesh') return meshVisual(v);
   var g;
   if (v.shape === 'cylinder') {
     g = new THREE.CylinderBufferGeometry(v.size[0], v.size[0], v.size[1], 32);
     g.rotateX(Math.PI / 2);  // three's cylinder is along y, URDF's along z
   } else if (v.shape === 'sphere') {
     g = new THREE.SphereBufferGeometry(v.size[0], 32, 16);
   } else {
     g = new THREE.BoxBufferGeometry(v.size[0], v.size[1], v.size[2]);
   }
   var mesh = new THREE.Mesh(g, material(v.rgba));
   place(mesh, v.origin);
   return mesh;
 }

 var frames = decode(D.frames, Float32Array), times = decode(D.times, Float64Array), n = D.frameCount;
 var stride = D.stride, N = D.links.length;
 K.frameCount = n;
 document.getElementById('title').textContent = D.title;
 document.getElementById('note').textContent = D.note;
 document.title = D.title;

 var view = document.getElementById('view');
 var renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
 renderer.setPixelRatio(window.devicePixelRatio || 1);
 renderer.setClearColor(0xf4f5f7);
 view.appendChild(renderer.domElement);
 var scene = new THREE.Scene();
 scene.add(new THREE.AmbientLight(0xffffff, 0.55));
 var sun = new THREE.DirectionalLight(0xffffff, 0.6);
 sun.position.set(1, -2, 3);
 scene.add(sun);
 var camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1000);
 camera.up.set(0, 0, 1);  // z up, as the URDF's world
 var objects = [];
 function add(object, name) { object.name = name; scene.add(object); objects.push(object); return object; }

 // The size of everything the run shows: the camera's distance, the markers' and arrows' scale.
 var lo = new THREE.Vector3(Infinity, Infinity, Infinity), hi = lo.clone().negate(), p = new THREE.Vector3();
 for (var k = 0; k < n; ++k)
   for (var i = 0; i <= N; ++i) {
     var o = k * stride + (i === 0 ? 0 : 3 + 7 * (i - 1));
     if (isNaN(frames[o])) continue;
     p.set(frames[o], frames[o + 1], frames[o + 2]);
     lo.min(p); hi.max(p);
   }
 if (!(hi.x >= lo.x)) { lo.set(-1, -1, -1); hi.set(1, 1, 1); }
 var centre = lo.clone().add(hi).multiplyScalar(0.5);
 var size = Math.max(hi.clone().sub(lo).length(), 0.2);

 var links = D.links.map(function (link) {
   var group = new THREE.Group();
   link.visuals.forEach(function (v) { group.add(visualMesh(v)); });
   return add(group, 'link ' + link.name);
 });
 // The meshes as drawn, for the tests: their vertices and their box in the link's frame (the
 // links are still at the origin here).
 K.meshes = [];
 links.forEach(function (group, i) {
   group.updateMatrixWorld(true);
   D.links[i].visuals.forEach(function (v, j) {
     if (v.shape !== 'mesh') return;
     var object = group.children[j], count = 0, box = new THREE.Box3().setFromObject(object);
     object.traverse(function (o) { if (o.isMesh) count += o.geometry.attributes.position.count; });
     K.meshes.push({ link: D.links[i].name, file: v.file, vertices: count,
                     box: box.isEmpty() ? null : [box.min.x, box.min.y, box.min.z, box.max.x, box.max.y, box.max.z] });
   });
 });
 var axes = new THREE.AxesHelper(0.25 * size);
 if (links.length) { links[0].add(axes); objects.push(axes); axes.name = 'base frame'; }
 var target = null, targetVisuals = [];
 if (D.target) {
   target = new THREE.Group();
   // A rigid target read from a URDF: its links' visuals, given in the target's frame.
   targetVisuals = (D.target.visuals || []).map(function (v) { var o = visualMesh(v); target.add(o); return o; });
   if (!targetVisuals.length) {  // its box of inertia
     var box = new THREE.Mesh(new THREE.BoxBufferGeometry(D.target.size[0], D.target.size[1], D.target.size[2]),
                              material([1.0, 0.5, 0.05, 0.55]));
     place(box, D.target.origin);
     target.add(box);
   }
   target.add(new THREE.AxesHelper(0.5 * Math.max(D.target.size[0], D.target.size[1], D.target.size[2])));
   add(target, 'target');
 }
 var contact = add(new THREE.Mesh(new THREE.SphereBufferGeometry(0.015 * size, 16, 12),
                                  new THREE.MeshBasicMaterial({ color: 0xd62728 })), 'contact point');
 var path = [];
 for (var k2 = 0; k2 < n; ++k2) {
   var c = k2 * stride;
   if (!isNaN(frames[c])) path.push(new THREE.Vector3(frames[c], frames[c + 1], frames[c + 2]));
 }
 add(new THREE.Line(new THREE.BufferGeometry().setFromPoints(path),
                    new THREE.LineBasicMaterial({ color: 0x7f3fbf })), 'hand path');

 // The contact instant: the first frame at or after it.
 var kImpact = -1;
 if (D.tCapture !== null)
   for (var k3 = 0; k3 < n; ++k3) if (times[k3] >= D.tCapture - 1e-12) { kImpact = k3; break; }
 var arrow = null, legend = 'robot: URDF visuals (grey boxes: boxes of inertia); orange: target; red: contact point; purple: the hand\'s path';
 if (D.impulse && kImpact >= 0) {
   var J = new THREE.Vector3(D.impulse[0], D.impulse[1], D.impulse[2]), magnitude = J.length();
   var scale = magnitude > 0 ? 0.3 * size / magnitude : 1;  // [m per N s]
   var at = kImpact * stride;
   arrow = add(new THREE.ArrowHelper(J.clone().normalize(), new THREE.Vector3(frames[at], frames[at + 1], frames[at + 2]),
                                     Math.max(magnitude * scale, 1e-6), 0xe6a100, 0.08 * size, 0.04 * size), 'impulse');
   legend += '; yellow arrow: the impulse on the robot at the capture, ' + magnitude.toPrecision(4) +
             ' N s, drawn at ' + scale.toPrecision(3) + ' m per N s';
 }
 document.getElementById('legend').textContent = legend;

 // --- A free-floating target's links, the grasp frame, a failed approach's closest distance ---
 // A frame holds, after the robot's links (and a rigid target's frame), a free-floating target's
 // link poses; the grasp frame rides on the target's frame (a rigid target's, or the base's).
 var targetLinks = (D.targetLinks || []).map(function (link) {
   var group = new THREE.Group();
   link.visuals.forEach(function (v) { group.add(visualMesh(v)); });
   return add(group, 'target link ' + link.name);
 });
 var targetLinksAt = 3 + 7 * N + (D.target ? 7 : 0);
 if (targetLinks.length) {  // the camera frames the target's links too
   for (var kt = 0; kt < n; ++kt)
     for (var it = 0; it < targetLinks.length; ++it) {
       var ot = kt * stride + targetLinksAt + 7 * it;
       if (!isNaN(frames[ot])) { p.set(frames[ot], frames[ot + 1], frames[ot + 2]); lo.min(p); hi.max(p); }
     }
   centre = lo.clone().add(hi).multiplyScalar(0.5);
   size = Math.max(hi.clone().sub(lo).length(), 0.2);
 }
 var graspHolder = target || targetLinks[0] || null, graspAxes = null;
 if (D.grasp && graspHolder) {
   graspAxes = new THREE.AxesHelper(0.12 * size);
   place(graspAxes, D.grasp.pose);
   graspHolder.add(graspAxes);
   objects.push(graspAxes);
   graspAxes.name = 'grasp frame';
   document.getElementById('legend').textContent += '; small axes on the target: the grasp frame';
 }
 if (targetLinks.length)
   document.getElementById('legend').textContent += '; orange links: the free-floating target (its URDF visuals, or boxes of inertia)';
 function poseTargetLinks(f) {
   for (var i = 0; i < targetLinks.length; ++i) {
     var o = f + targetLinksAt + 7 * i;
     targetLinks[i].visible = !isNaN(frames[o]);
     if (targetLinks[i].visible) place(targetLinks[i], frames.subarray(o, o + 7));
   }
 }
 function poseArray(o) {
   var a = [];
   for (var i = 0; i < 7; ++i) a.push(frames[o + i]);
   return isNaN(a[0]) ? null : a;
 }
 // The world pose [x, y, z, qx, qy, qz, qw] of the grasp frame at frame k (null: none drawn).
 K.graspFrame = function (k) {
   if (!graspAxes) return null;
   var holder = poseArray(k * stride + (target ? 3 + 7 * N : targetLinksAt));
   if (!holder) return null;
   var g = D.grasp.pose, m = new THREE.Matrix4().compose(new THREE.Vector3(holder[0], holder[1], holder[2]),
       new THREE.Quaternion(holder[3], holder[4], holder[5], holder[6]), new THREE.Vector3(1, 1, 1));
   m.multiply(new THREE.Matrix4().compose(new THREE.Vector3(g[0], g[1], g[2]), new THREE.Quaternion(g[3], g[4], g[5], g[6]),
                                          new THREE.Vector3(1, 1, 1)));
   var p = new THREE.Vector3(), q = new THREE.Quaternion(), s = new THREE.Vector3();
   m.decompose(p, q, s);
   return [p.x, p.y, p.z, q.x, q.y, q.z, q.w];
 };
 K.targetLinkCount = targetLinks.length;
 // --- The target's URDF visuals (issue 27, item 2), for the tests: a rigid target's visuals (their
 // world pose and box at frame k) and the target's meshes as drawn (rigid or free-floating).
 if (targetVisuals.length)
   document.getElementById('legend').textContent += '; orange: the rigid target drawn with its URDF visuals';
 if (D.targetDrift)
   document.getElementById('legend').textContent += '; after the point impact the free-floating target is drawn as one ' +
       'rigid body, its joints frozen, drifting torque-free from its base twist after the impact (the run does not ' +
       'compute its own motion)';
 K.targetDrift = !!D.targetDrift;
 K.targetVisualCount = targetVisuals.length;
 K.targetPose = function (k) { return target ? poseArray(k * stride + 3 + 7 * N) : null; };
 K.targetVisualPose = function (k, i) {
   var t = K.targetPose(k), v = D.target.visuals[i].origin;
   if (!t) return null;
   var m = new THREE.Matrix4().compose(new THREE.Vector3(t[0], t[1], t[2]), new THREE.Quaternion(t[3], t[4], t[5], t[6]),
                                       new THREE.Vector3(1, 1, 1));
   m.multiply(new THREE.Matrix4().compose(new THREE.Vector3(v[0], v[1], v[2]), new THREE.Quaternion(v[3], v[4], v[5], v[6]),
                                          new THREE.Vector3(1, 1, 1)));
   var p = new THREE.Vector3(), q = new THREE.Quaternion(), s = new THREE.Vector3();
   m.decompose(p, q, s);
   return [p.x, p.y, p.z, q.x, q.y, q.z, q.w];
 };
 // The world boxes [min x y z, max x y z] of the visuals as drawn at the current frame (setFrame).
 K.targetVisualBoxes = function () {
   return targetVisuals.map(function (o) {
     o.updateMatrixWorld(true);
     var b = new THREE.Box3().setFromObject(o);
     return b.isEmpty() ? null : [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z];
   });
 };
 K.targetMeshes = [];
 function countTargetMeshes(visuals, objects, link) {
   visuals.forEach(function (v, j) {
     if (v.shape !== 'mesh') return;
     var count = 0;
     objects[j].traverse(function (o) { if (o.isMesh) count += o.geometry.attributes.position.count; });
     K.targetMeshes.push({ link: link || v.link, file: v.file, vertices: count });
   });
 }
 if (targetVisuals.length) countTargetMeshes(D.target.visuals, targetVisuals, null);
 targetLinks.forEach(function (group, i) { countTargetMeshes(D.targetLinks[i].visuals, group.children, D.targetLinks[i].name); });
 // --- end of the target's URDF visuals
 K.targetLinkPose = function (k, i) { return poseArray(k * stride + targetLinksAt + 7 * i); };
 // A failed approach: how close the hand came, when, and the frame nearest that instant.
 K.closest = null;
 if (D.closest) {
   var kClosest = 0;
   for (var kc = 1; kc < n; ++kc) if (Math.abs(times[kc] - D.closest.time) < Math.abs(times[kClosest] - D.closest.time)) kClosest = kc;
   K.closest = { distance: D.closest.distance, time: D.closest.time, frame: kClosest };
   var line = document.createElement('div');
   line.id = 'closest';
   line.textContent = 'Closest to the grasp point: ' + D.closest.distance.toPrecision(4) + ' m at t = ' +
                      D.closest.time.toFixed(3) + ' s (frame ' + kClosest + ')';
   document.getElementById('note').appendChild(line);
 }

 var controls = new THREE.OrbitControls(camera, renderer.domElement);
 controls.target.copy(centre);
 camera.position.copy(centre).add(new THREE.Vector3(1.2 * size, -1.6 * size, 0.9 * size));
 controls.update();

 // The phases on the time line.
 var bar = document.getElementById('phasebar'), t0 = times[0], span = Math.max(times[n - 1] - t0, 1e-12);
 for (var s = 0; s < n; ) {
   var e = s;
   while (e + 1 < n && D.phases[e + 1] === D.phases[s]) ++e;
   var piece = document.createElement('div');
   piece.style.left = (100 * (times[s] - t0) / span) + '%';
   piece.style.width = Math.max(100 * (times[Math.min(e + 1, n - 1)] - times[s]) / span, 0.3) + '%';
   piece.style.background = PHASE_COLOURS[D.phases[s]] || '#999';
   piece.title = D.phaseNames[D.phases[s]];
   bar.appendChild(piece);
   s = e + 1;
 }

 function resize() {
   var w = view.clientWidth || 800, h = view.clientHeight || 500;
   renderer.setSize(w, h);
   camera.aspect = w / h;
   camera.updateProjectionMatrix();
 }
 var current = 0, baseAt = new THREE.Vector3(), slider = document.getElementById('slider');
 slider.max = String(n - 1);
 function setFrame(k) {
   k = Math.max(0, Math.min(n - 1, Math.round(k)));
   var f = k * stride;
   for (var i = 0; i < N; ++i) {
     var o = f + 3 + 7 * i;
     links[i].visible = !isNaN(frames[o]);
     if (links[i].visible) place(links[i], frames.subarray(o, o + 7));
   }
   if (target) {
     var t = f + 3 + 7 * N;
     target.visible = !isNaN(frames[t]);
     if (target.visible) place(target, frames.subarray(t, t + 7));
   }
   poseTargetLinks(f);
   contact.visible = !isNaN(frames[f]);
   contact.position.set(frames[f], frames[f + 1], frames[f + 2]);
   if (arrow) arrow.visible = k >= kImpact;
   if (document.getElementById('follow').checked && links.length) {
     var delta = links[0].position.clone().sub(baseAt);
     camera.position.add(delta);
     controls.target.add(delta);
   }
   if (links.length) baseAt.copy(links[0].position);
   current = k;
   slider.value = String(k);
   document.getElementById('time').textContent = 't = ' + times[k].toFixed(3) + ' s (' +
       D.phaseNames[D.phases[k]] + '), frame ' + k + ' of ' + n;
   controls.update();
   renderer.render(scene, camera);
   if (plots) plots.cursor(k);  // the linked plots' cursor
 }
 K.setFrame = setFrame;
 K.contactPoint = function (k) { var f = k * stride; return [frames[f], frames[f + 1], frames[f + 2]]; };
 K.time = function (k) { return times[k]; };
 K.objectCount = function () { return objects.length; };
 K.impactFrame = kImpact;

 var playing = false, speed = 1, simTime = t0, last = null;
 document.getElementById('play').onclick = function () {
   playing = !playing;
   if (playing && current >= n - 1) current = 0;
   simTime = times[current];
   this.textContent = playing ? 'pause' : 'play';
 };
 document.getElementById('speed').onchange = function () { speed = parseFloat(this.value); };
 document.getElementById('impact').onclick = function () { if (kImpact >= 0) setFrame(kImpact); };
 document.getElementById('impact').disabled = kImpact < 0;
 slider.oninput = function () { setFrame(parseInt(this.value, 10)); simTime = times[current]; };
 controls.addEventListener('change', function () { renderer.render(scene, camera); });
 window.addEventListener('resize', function () { resize(); setFrame(current); });
 function tick(now) {
   if (playing && last !== null) {
     simTime += speed * (now - last) / 1000;
     var k = current;
     while (k + 1 < n && times[k + 1] <= simTime) ++k;
     if (k !== current) setFrame(k);
     if (k >= n - 1) { playing = false; document.getElementById('play').textContent = 'play'; }
   }
   last = now;
   requestAnimationFrame(tick);
 }
 var plots = kdlSpacePlots(K, D, times, slider, PHASE_COLOURS);  // the linked plots (before the view's size)
 resize();
 var hash = /[#&](frame|selftest)=(\w+)/.exec(location.hash);
 var start = hash ? (hash[2] === 'last' ? n - 1 : parseInt(hash[2], 10)) : 0;
 setFrame(start);
 K.current = function () { return current; };
 requestAnimationFrame(tick);
}
// #selftest=K: the state at frame K as JSON in <pre id="selftest"> (what `chromium --dump-dom`
// prints for the tests), written whether or not the page could start.
(function () {
 var K = window.kdlSpace;
 try { kdlSpaceMain(); } catch (e) { K.errors.push('the page could not start: ' + (e && e.message)); }
 K.readyMs = performance.now();  // [ms] from the navigation's start: how long the page took to open
 K.ready = true;
 if (!/[#&]selftest=/.test(location.hash)) return;
 var ok = typeof K.current === 'function', k = ok ? K.current() : -1;
 document.getElementById('selftest').textContent = JSON.stringify({
   errors: K.errors, objectCount: ok ? K.objectCount() : 0, frameCount: K.frameCount, frame: k,
   time: ok ? K.time(k) : null, contactPoint: ok ? K.contactPoint(k) : null, impactFrame: ok ? K.impactFrame : -1,
   meshes: K.meshes || [],
   graspFrame: ok && K.graspFrame ? K.graspFrame(k) : null, closest: ok ? K.closest : null,
   note: document.getElementById('note').textContent, readyMs: K.readyMs,
   targetVisualCount: K.targetVisualCount || 0, targetMeshes: K.targetMeshes || [],
   targetPose: ok && K.targetPose ? K.targetPose(k) : null,
   targetVisualPoses: ok && K.targetVisualPose ? Array.apply(null, Array(K.targetVisualCount)).map(function (_, i) { return K.targetVisualPose(k, i); }) : [],
   targetVisualBoxes: ok && K.targetVisualBoxes ? K.targetVisualBoxes() : [],
   targetLinkPoses: ok && K.targetLinkPose ? Array.apply(null, Array(K.targetLinkCount)).map(function (_, i) { return K.targetLinkPose(k, i); }) : [] });
})();
