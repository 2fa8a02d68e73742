(function () {
  // moves the parts of one .anim block to the frame its range control selects; every part names the
  // points it joins (data-points) or stands on (data-index), the frames' points come as JSON
  var root = document.currentScript.closest(".anim");
  var F = JSON.parse(root.querySelector("script[type='application/json']").textContent);
  var n = F.labels.length, timer = null;
  var range = root.querySelector("input[type=range]"), label = root.querySelector("output"),
      play = root.querySelector("button"), note = root.querySelector("[data-role='note']");
  var links = Array.prototype.slice.call(root.querySelectorAll("[data-points]"));
  var dots = Array.prototype.slice.call(root.querySelectorAll("[data-index]"));
  function point(k, i) {
    var x = F.points[k][2 * i], y = F.points[k][2 * i + 1];
    return (x === null || y === null) ? null : [x, y];
  }
  function show(k) {
    links.forEach(function (el) {
      var ps = el.getAttribute("data-points").split(" ").map(function (i) { return point(k, +i); });
      if (ps.some(function (p) { return p === null; })) { el.style.visibility = "hidden"; return; }
      el.style.visibility = "visible";
      if (el.tagName === "line") {
        el.setAttribute("x1", ps[0][0]); el.setAttribute("y1", ps[0][1]);
        el.setAttribute("x2", ps[1][0]); el.setAttribute("y2", ps[1][1]);
      } else {
        el.setAttribute("points", ps.map(function (p) { return p.join(","); }).join(" "));
      }
    });
    dots.forEach(function (el) {
      var p = point(k, +el.getAttribute("data-index"));
      el.style.visibility = p === null ? "hidden" : "visible";
      if (p !== null) { el.setAttribute("cx", p[0]); el.setAttribute("cy", p[1]); }
    });
    note.style.visibility = F.points[k].indexOf(null) >= 0 ? "visible" : "hidden";
    label.textContent = F.labels[k];
  }
  range.addEventListener("input", function () { show(parseInt(range.value, 10)); });
  play.addEventListener("click", function () {
    if (timer) { clearInterval(timer); timer = null; play.textContent = "play"; return; }
    play.textContent = "pause";
    timer = setInterval(function () {
      range.value = (parseInt(range.value, 10) + 1) % n;
      show(parseInt(range.value, 10));
    }, 40);
  });
  show(parseInt(range.value, 10));
})();
