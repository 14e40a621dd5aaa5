// The page of `--html` (html_writer.cpp): its head (the error hooks, before three.js loads) and
// its body (the view, the controls and the script that poses the frames). The data
// (window.KDL_DATA) and three.js are written between the two.
#pragma once

namespace kdl_space::cli {

inline const char* const kHtmlHead = R"HTML(<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>kdl_space</title>
<style>
 html, body { margin: 0; height: 100%; font: 13px sans-serif; background: #f4f5f7; color: #222; }
 #view { position: absolute; top: 0; left: 0; right: 0; bottom: 74px; }
 #bar { position: absolute; left: 0; right: 0; bottom: 0; height: 74px; padding: 4px 10px; box-sizing: border-box; background: #fff; border-top: 1px solid #ccc; }
 #slider { width: 100%; margin: 0; }
 #phasebar { position: relative; height: 8px; margin: 0 8px; }
 #phasebar div { position: absolute; top: 0; height: 8px; }
 #info { position: absolute; top: 6px; left: 10px; background: rgba(255,255,255,0.85); padding: 4px 8px; border-radius: 4px; max-width: 60%; }
 #note { color: #b00; font-weight: bold; }
 #selftest { display: none; }
 button, select, label { margin-right: 8px; }
</style>
<script>
 // The page's errors, kept for its tests (window.kdlSpace.errors) from the first script on.
 window.kdlSpace = { ready: false, errors: [], frameCount: 0 };
 window.addEventListener('error', function (e) { window.kdlSpace.errors.push(String(e.message || e)); });
 (function () {
   var original = console.error;
   console.error = function () {
     window.kdlSpace.errors.push(Array.prototype.map.call(arguments, String).join(' '));
     original.apply(console, arguments);
   };
 })();
</script>
)HTML";

inline const char* const kHtmlBody = R"HTML(</head><body>
<div id="view"></div>
<div id="info"><div id="title"></div><div id="note"></div><div id="time"></div><div id="legend"></div></div>
<div id="bar">
 <div id="phasebar"></div>
 <input id="slider" type="range" min="0" max="0" value="0">
 <div>
  <button id="play">play</button>
  <label>speed <select id="speed"><option>0.25</option><option>0.5</option><option selected>1</option><option>2</option><option>4</option><option>10</option></select></label>
  <button id="impact">step to impact</button>
  <label><input id="follow" type="checkbox"> camera follows the base</label>
  <span>drag: orbit, wheel: zoom, right drag: pan</span>
 </div>
</div>
<pre id="selftest"></pre>
<script>
function kdlSpaceMain() {
 'use strict';
 var K = window.kdlSpace, D = window.KDL_DATA;
 var PHASE_COLOURS = ['#4c78a8', '#d62728', '#59a14f', '#9c9c9c'];
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
 function visualMesh(v) {
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
 var axes = new THREE.AxesHelper(0.25 * size);
 if (links.length) { links[0].add(axes); objects.push(axes); axes.name = 'base frame'; }
 var target = null;
 if (D.target) {
   target = new THREE.Group();
   var box = new THREE.Mesh(new THREE.BoxBufferGeometry(D.target.size[0], D.target.size[1], D.target.size[2]),
                            material([1.0, 0.5, 0.05, 0.55]));
   place(box, D.target.origin);
   target.add(box);
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
   graspFrame: ok && K.graspFrame ? K.graspFrame(k) : null, closest: ok ? K.closest : null,
   note: document.getElementById('note').textContent, readyMs: K.readyMs,
   targetLinkPoses: ok && K.targetLinkPose ? Array.apply(null, Array(K.targetLinkCount)).map(function (_, i) { return K.targetLinkPose(k, i); }) : [] });
})();
</script>
</body></html>
)HTML";

}  // namespace kdl_space::cli
