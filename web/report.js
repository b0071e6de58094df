// `edgeslam report`: draws a finished run's charts with uPlot (inlined into the page with this
// script) from the data the command put in `window.EDGESLAM_REPORT`. No requests of any kind.
(function () {
  'use strict';
  const report = window.EDGESLAM_REPORT;
  const AXIS = { stroke: '#3b4350', grid: { stroke: '#e4e7ec' } };
  const width = () => Math.min(900, document.body.clientWidth - 40);

  function section(title, note) {
    const el = document.createElement('section');
    el.innerHTML = `<h2></h2><p class="note"></p><div class="chart"></div>`;
    el.querySelector('h2').textContent = title;
    el.querySelector('.note').textContent = note || '';
    document.getElementById('charts').appendChild(el);
    return el.querySelector('.chart');
  }

  function lineChart(title, note, x, series, xLabel, yLabel) {
    new uPlot({
      width: width(), height: 260, scales: { x: { time: false } },
      axes: [{ ...AXIS, label: xLabel }, { ...AXIS, label: yLabel, size: 60 }],
      series: [{ label: xLabel }, ...series.map((s) => ({ label: s.label, stroke: s.color, width: 1.5,
        paths: s.steps ? uPlot.paths.stepped({ align: 1 }) : undefined, points: { show: false } }))],
    }, [x, ...series.map((s) => s.values)], section(title, note));
  }

  // An x-y path in uPlot's faceted mode (the positions are not ordered by x).
  function xyPath(u, seriesIdx) {
    const [xs, ys] = u.data[seriesIdx];
    const path = new Path2D();
    for (let i = 0; i < xs.length; ++i) {
      const px = u.valToPos(xs[i], 'x', true), py = u.valToPos(ys[i], 'y', true);
      if (i === 0) path.moveTo(px, py); else path.lineTo(px, py);
    }
    return { stroke: path, fill: null, clip: null, flags: 0 };
  }

  function topView(view) {
    const all = [...view.truth_x, ...view.estimate_x], allY = [...view.truth_y, ...view.estimate_y];
    let [x0, x1] = [Math.min(...all), Math.max(...all)], [y0, y1] = [Math.min(...allY), Math.max(...allY)];
    const w = width(), h = 420;
    // Equal metres per pixel on both axes, with a margin.
    const perPixel = 1.1 * Math.max((x1 - x0) / w, (y1 - y0) / h, 1e-6);
    const cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
    [x0, x1] = [cx - perPixel * w / 2, cx + perPixel * w / 2];
    [y0, y1] = [cy - perPixel * h / 2, cy + perPixel * h / 2];
    const facets = [{ scale: 'x', auto: false }, { scale: 'y', auto: false }];
    new uPlot({
      mode: 2, width: w, height: h,
      scales: { x: { time: false, range: [x0, x1] }, y: { range: [y0, y1] } },
      axes: [{ ...AXIS, label: `${view.axes[0]} (m)` }, { ...AXIS, label: `${view.axes[1]} (m)`, size: 60 }],
      legend: { live: false },
      series: [{}, { label: 'ground truth', stroke: '#e0891a', width: 2, facets, paths: xyPath, points: { show: false } },
        { label: `estimate (${view.align} aligned)`, stroke: '#1f7ae0', width: 2, facets, paths: xyPath, points: { show: false } }],
    }, [null, [view.truth_x, view.truth_y], [view.estimate_x, view.estimate_y]],
    section('Trajectory, top view', `the estimate at frame time aligned to the ground truth; axes ${view.axes.join(' and ')} of the ground-truth frame`));
  }

  if (report.top_view) topView(report.top_view);
  if (report.error) {
    lineChart('Position error over time', `ATE RMSE ${report.error.rmse_m.toFixed(4)} m over ${report.error.t.length} poses`,
      report.error.t, [{ label: 'error (m)', color: '#d2342c', values: report.error.error_m }], 'time (s)', 'm');
  }
  const f = report.frames;
  if (f) {
    lineChart('Per-frame latency', 'client: the frame\'s processing on the client; end-to-end: from its arrival to its pose',
      f.frame, [{ label: 'client ms', color: '#1f7ae0', values: f.client_ms }, { label: 'e2e ms', color: '#d2342c', values: f.e2e_ms }],
      'frame', 'ms');
    if (f.uplink_bytes.some((v) => v > 0) || f.downlink_bytes.some((v) => v > 0)) {
      lineChart('Bytes over the link', 'cumulative, as the client counted them', f.frame,
        [{ label: 'uplink', color: '#1f7ae0', values: f.uplink_bytes }, { label: 'downlink', color: '#2a9d4b', values: f.downlink_bytes }],
        'frame', 'bytes');
    }
    if (f.adaptation_row.some((v) => v >= 0)) {
      lineChart('Adaptation decisions', 'the Table I row in use at each frame (1 = richest)', f.frame,
        [{ label: 'row', color: '#7d3cd6', steps: true, values: f.adaptation_row.map((v) => (v >= 0 ? v + 1 : null)) }], 'frame', 'row');
    }
    if (f.features_culled.some((v) => v > 0)) {
      lineChart('Semantic culling', 'features dropped as on movable objects, per frame', f.frame,
        [{ label: 'culled', color: '#c2185b', values: f.features_culled }], 'frame', 'features');
    }
  }
})();
