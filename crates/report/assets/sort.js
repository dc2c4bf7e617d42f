// cadmorph report tables: click a column header to sort by it (numbers as numbers,
// ascending then descending). Works without WebGL.
(function () {
  "use strict";
  // Sortable tables: click a header to sort by that column (numbers as numbers).
  Array.prototype.forEach.call(document.querySelectorAll("table.sortable th"), function (th) {
    th.addEventListener("click", function () {
      var table = th.closest("table"), body = table.tBodies[0], idx = Array.prototype.indexOf.call(th.parentNode.children, th);
      var rows = Array.prototype.slice.call(body.rows), asc = th.dataset.sort !== "asc";
      rows.sort(function (a, b) {
        var x = a.cells[idx].dataset.v || a.cells[idx].textContent, y = b.cells[idx].dataset.v || b.cells[idx].textContent;
        var nx = parseFloat(x), ny = parseFloat(y), c = !isNaN(nx) && !isNaN(ny) ? nx - ny : x.localeCompare(y);
        return asc ? c : -c;
      });
      th.dataset.sort = asc ? "asc" : "desc";
      rows.forEach(function (r) { body.appendChild(r); });
    });
  });

})();
