// Click to zoom a figure: a link with class hh-zoom (the study figures, docs/_hooks/studies.py) opens its image
// at its own size over the page; a click anywhere on it, or Escape, closes it. Without JavaScript the link opens
// the image file itself.
(function () {
  function close() {
    var o = document.querySelector(".hh-zoom-overlay");
    if (o) o.remove();
  }
  document.addEventListener("click", function (e) {
    if (e.target.closest(".hh-zoom-overlay")) {
      e.preventDefault();
      close();
      return;
    }
    var a = e.target.closest("a.hh-zoom");
    if (!a) return;
    e.preventDefault();
    var o = document.createElement("div");
    o.className = "hh-zoom-overlay";
    var img = document.createElement("img");
    img.src = a.getAttribute("href");
    var inner = a.querySelector("img");
    img.alt = inner ? inner.alt : "";
    o.appendChild(img);
    document.body.appendChild(o);
  });
  document.addEventListener("keydown", function (e) {
    if (e.key === "Escape") close();
  });
})();
