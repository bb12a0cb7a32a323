// uPlot in a Preact component: sized to its container (ResizeObserver, so a
// phone turned sideways re-flows the plot), data pushed from outside through
// a ref (live plots update without re-rendering the page).
import { useEffect, useRef } from 'preact/hooks';
import uPlot from 'uplot';

export function Plot({ options, data, height = 220, plotRef, label }) {
  const box = useRef(null);
  const plot = useRef(null);

  useEffect(() => {
    const el = box.current;
    const width = Math.max(200, el.clientWidth);
    plot.current = new uPlot({ ...options, width, height }, data || options.series.map(() => []), el);
    if (plotRef) plotRef.current = plot.current;
    const ro = new ResizeObserver(() => {
      const w = Math.max(200, el.clientWidth);
      if (plot.current && Math.abs(plot.current.width - w) > 1) plot.current.setSize({ width: w, height });
    });
    ro.observe(el);
    return () => { ro.disconnect(); plot.current.destroy(); plot.current = null; if (plotRef) plotRef.current = null; };
  }, [options]);

  useEffect(() => {
    if (plot.current && data) plot.current.setData(data);
  }, [data]);

  return <div class="plot" ref={box} role="img" aria-label={label || 'plot'} />;
}

export const PALETTE = ['#1f6feb', '#d1242f', '#1a7f37', '#9a6700', '#8250df', '#bf3989', '#0a7480', '#6e7781'];
