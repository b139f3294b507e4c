// Calibench report plots: Chart.js (Debian's libjs-chart.js, inlined above) over REPORT: one
// camera's data, or a rig's ({cameras: [...]}, each with the prefix of its canvases' ids).
(function () {
  if (typeof Chart === "undefined") return;
  Chart.defaults.animation = false;  // drawn at once: printing and screenshots see the plots
  Chart.defaults.font.family = "DejaVu Sans, sans-serif";
  const reports = REPORT.cameras || [Object.assign({ prefix: "" }, REPORT)];
  reports.forEach(camera => draw(camera, camera.prefix));
})();

function draw(REPORT, prefix) {
  if (REPORT.kind === "lrf") return drawLrf(REPORT);
  const solved = REPORT.pairs.filter(p => p.solved);
  const ids = solved.map(p => p.id);
  const colour = p => (p.disagrees ? "#c0392b" : "#3b6ea5");
  function chart(id, config) {
    const canvas = document.getElementById(prefix + id);
    if (!canvas) return;
    config.options = Object.assign({ responsive: true, maintainAspectRatio: false }, config.options);
    new Chart(canvas, config);
  }
  const title = text => ({ display: true, text: text });
  chart("residuals", {
    type: "bar",
    data: { labels: ids, datasets: [
      { label: "plane angle [deg]", data: solved.map(p => p.angle_deg), backgroundColor: "#3b6ea5", yAxisID: "a" },
      { label: "held out [deg]", data: solved.map(p => p.heldout_angle_deg), backgroundColor: "#9db7d5", yAxisID: "a" },
      { label: "plane offset [mm]", data: solved.map(p => p.distance_mm), backgroundColor: "#d98c2b", yAxisID: "d", type: "line", showLine: false, pointRadius: 3 },
      { label: "held out offset [mm]", data: solved.map(p => p.heldout_distance_mm), backgroundColor: "#c0392b", borderColor: "#c0392b", yAxisID: "d", type: "line", showLine: false, pointRadius: 3, pointStyle: "triangle" } ] },
    options: { plugins: { title: title("Residuals per pair: training and held out") },
               scales: { a: { position: "left", title: title("deg") }, d: { position: "right", title: title("mm"), grid: { drawOnChartArea: false } } } } });
  chart("weights", {
    type: "bar",
    data: { labels: ids, datasets: [{ label: "robust weight", data: solved.map(p => p.weight), backgroundColor: solved.map(colour) }] },
    options: { plugins: { title: title("Robust weight per pair") }, scales: { y: { min: 0, max: 1.05 } } } });
  chart("convergence", {
    type: "line",
    data: { labels: REPORT.cost.map((_, i) => i), datasets: [{ label: "cost", data: REPORT.cost, borderColor: "#3b6ea5", pointRadius: 2 }] },
    options: { plugins: { title: title("Solver convergence") }, scales: { x: { title: title("iteration") }, y: { type: "logarithmic", title: title("cost") } } } });
  const axes = ["x", "y", "z"], palette = ["#c0392b", "#3a8d3a", "#3b6ea5"];
  const sigmaSets = [];
  axes.forEach((a, i) => sigmaSets.push({ label: "σ t" + a + " [mm]", data: REPORT.sigma.map(s => s.t_mm[i]), borderColor: palette[i], yAxisID: "t", pointRadius: 2 }));
  axes.forEach((a, i) => sigmaSets.push({ label: "σ r" + a + " [deg]", data: REPORT.sigma.map(s => s.r_deg[i]), borderColor: palette[i], borderDash: [5, 4], yAxisID: "r", pointRadius: 2 }));
  chart("sigma", {
    type: "line",
    data: { labels: REPORT.sigma.map(s => s.pairs), datasets: sigmaSets },
    options: { plugins: { title: title("σ as pairs accumulate (capture order)") },
               scales: { x: { title: title("pairs") }, t: { type: "logarithmic", position: "left", title: title("mm") }, r: { type: "logarithmic", position: "right", title: title("deg"), grid: { drawOnChartArea: false } } } } });
  const [w, h] = REPORT.image_size;
  chart("coverage-image", {
    type: "scatter",
    data: { datasets: [{ label: "board centre in the image", data: solved.filter(p => p.image).map(p => ({ x: p.image[0], y: p.image[1], id: p.id })), backgroundColor: solved.filter(p => p.image).map(colour), pointRadius: 5 }] },
    options: { plugins: { title: title("Coverage: the image (" + w + " x " + h + " px)"), tooltip: { callbacks: { label: c => c.raw.id } } },
               scales: { x: { min: 0, max: w, title: title("u [px]") }, y: { min: 0, max: h, reverse: true, title: title("v [px]") } } } });
  chart("coverage-lidar", {
    type: "scatter",
    data: { datasets: [{ label: "board centre seen from the LiDAR", data: solved.filter(p => p.lidar).map(p => ({ x: p.lidar[0], y: p.lidar[1], id: p.id })), backgroundColor: solved.filter(p => p.lidar).map(colour), pointRadius: 5 }] },
    options: { plugins: { title: title("Coverage: the LiDAR's field"), tooltip: { callbacks: { label: c => c.raw.id } } },
               scales: { x: { reverse: true, title: title("azimuth [deg] (left is +)") }, y: { title: title("elevation [deg]") } } } });
  const offset = REPORT.time_offset;
  if (offset) {
    // Δχ² + 1, so that the best offset (Δχ² = 0) has a place on the log scale.
    const profile = offset.offset_ms.map((x, i) => ({ x: x, y: offset.chi2_above_lowest[i] + 1 }));
    const sets = [{ label: "Δχ² + 1: the planes' disagreement above the best offset's", data: profile, borderColor: "#3b6ea5", backgroundColor: "#3b6ea5", showLine: true, pointRadius: 2 }];
    if (offset.estimate_ms !== undefined) {
      const top = Math.max(...offset.chi2_above_lowest) + 1;
      sets.push({ label: "estimate " + offset.estimate_ms.toFixed(1) + " ms", data: [{ x: offset.estimate_ms, y: 1 }, { x: offset.estimate_ms, y: top }], borderColor: "#c0392b", showLine: true, pointRadius: 0 });
      const low = offset.estimate_ms - 3 * offset.std_ms, high = offset.estimate_ms + 3 * offset.std_ms;
      sets.push({ label: "± 3σ (" + (3 * offset.std_ms).toFixed(1) + " ms)", data: [{ x: low, y: 1 }, { x: low, y: top }], borderColor: "#d98c2b", borderDash: [5, 4], showLine: true, pointRadius: 0 });
      sets.push({ label: "", data: [{ x: high, y: 1 }, { x: high, y: top }], borderColor: "#d98c2b", borderDash: [5, 4], showLine: true, pointRadius: 0 });
    }
    chart("time-offset-profile", {
      type: "scatter",
      data: { datasets: sets },
      options: { plugins: { title: title("The planes' disagreement against the camera - LiDAR time offset"), legend: { labels: { filter: item => item.text !== "" } } },
                 scales: { x: { title: title("camera - LiDAR [ms]") }, y: { type: "logarithmic", title: title("Δχ² + 1 (log)") } } } });
  }
}

// A 2D LRF report: the target's residual per observation (training and held out), the robust
// weights and the solver's convergence.
function drawLrf(REPORT) {
  const solved = REPORT.pairs.filter(p => p.solved);
  const ids = solved.map(p => p.id);
  const title = text => ({ display: true, text: text });
  function chart(id, config) {
    const canvas = document.getElementById(id);
    if (!canvas) return;
    config.options = Object.assign({ responsive: true, maintainAspectRatio: false }, config.options);
    new Chart(canvas, config);
  }
  chart("lrf-residuals", {
    type: "bar",
    data: { labels: ids, datasets: [
      { label: "training [mm]", data: solved.map(p => p.residual_mm), backgroundColor: "#3b6ea5" },
      { label: "held out [mm]", data: solved.map(p => p.heldout_mm), backgroundColor: solved.map(p => (p.disagrees ? "#c0392b" : "#9db7d5")) } ] },
    options: { plugins: { title: title(REPORT.residual + " per observation") }, scales: { y: { title: title("mm") } } } });
  chart("weights", {
    type: "bar",
    data: { labels: ids, datasets: [{ label: "robust weight", data: solved.map(p => p.weight), backgroundColor: "#3b6ea5" }] },
    options: { plugins: { title: title("Robust weight per observation (refined)") }, scales: { y: { min: 0, max: 1.05 } } } });
  chart("convergence", {
    type: "line",
    data: { labels: REPORT.cost.map((_, i) => i), datasets: [{ label: "cost", data: REPORT.cost, borderColor: "#3b6ea5", pointRadius: 2 }] },
    options: { plugins: { title: title("Solver convergence") }, scales: { x: { title: title("iteration") }, y: { type: "logarithmic", title: title("cost") } } } });
}
