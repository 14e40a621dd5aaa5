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
