// MathJax 3 for pymdownx.arithmatex (generic mode); the MathJax script itself is copied into the site from the
// django-static-mathjax wheel by docs/_hooks/site.py (offline, no CDN).
window.MathJax = {
  tex: {
    inlineMath: [["\\(", "\\)"]],
    displayMath: [["\\[", "\\]"]],
    processEscapes: true,
    processEnvironments: true
  },
  options: {
    ignoreHtmlClass: ".*|",
    processHtmlClass: "arithmatex"
  }
};

// MathJax typesets a page it is loaded on by itself. Material's document$ also emits on that first load: the
// re-render recipe (clearCache + typesetClear + typeset) run then dropped the CSS of the glyphs MathJax had just
// typeset, leaving every equation blank (mjx-containers without ink; tests/test_docs_browser.py). So re-typeset
// only when Material swaps in a new page without a reload (the navigation.instant feature, should it be enabled).
if (typeof document$ !== "undefined") {
  let firstPage = true;
  document$.subscribe(() => {
    if (firstPage) {
      firstPage = false;
      return;
    }
    if (window.MathJax && MathJax.typesetPromise) {
      MathJax.startup.promise.then(() => {
        MathJax.typesetClear();
        MathJax.texReset();
        return MathJax.typesetPromise();
      });
    }
  });
}
