// Small pieces used on every page.
import { useEffect, useRef } from 'preact/hooks';
import { elementType, formatScalar, formatValue } from '../lib/format.js';

// A value with its unit; forced values get a badge and the forced colour.
// For an array, `forced` may be one flag per element: only those are coloured.
// quality: the live hub's qualityOf(ref) (null: none known yet); a stale
// value is greyed and says why (stale, task stopped, driver not ok).
export function Value({ value, type, unit, forced, quality }) {
  const perElement = Array.isArray(forced) && Array.isArray(value) && forced.length === value.length;
  const f = Array.isArray(forced) ? forced.some(Boolean) : !!forced;
  const el = elementType(type);
  const stale = !!(quality && quality.stale);
  const cls = `value${f ? ' forced' : ''}${stale ? ' stale' : ''}`;
  return (
    <span class={cls} data-forced={f ? 'true' : 'false'} data-quality={quality ? quality.q : ''}
      title={stale ? `Not live: ${quality.text} (${(quality.ageMs / 1000).toFixed(1)} s old)` : undefined}>
      {perElement ? (
        <span class="num">{value.map((v, i) => (
          <>{i ? ', ' : ''}<span class={forced[i] ? 'forced-element' : 'element'}>{formatScalar(v, el)}</span></>
        ))}</span>
      ) : <span class={f ? 'num forced-element' : 'num'}>{formatValue(value, type)}</span>}
      {unit ? <span class="unit"> {unit}</span> : null}
      {f ? <span class="badge badge-forced" title="Forced: held at this value whatever the program writes, until unforced">F</span> : null}
      {stale ? <span class="badge badge-stale">{quality.text}</span> : null}
    </span>
  );
}

// A modal dialog on <dialog> (Esc closes it, focus stays inside).
export function Modal({ open, title, onClose, children, wide }) {
  const ref = useRef(null);
  useEffect(() => {
    const d = ref.current;
    if (!d) return;
    if (open && !d.open) d.showModal();
    if (!open && d.open) d.close();
  }, [open]);
  return (
    <dialog ref={ref} class={wide ? 'modal wide' : 'modal'} onClose={onClose} onCancel={onClose} aria-label={title}>
      <header class="modal-head">
        <h2>{title}</h2>
        <button type="button" class="btn-icon" aria-label="Close" onClick={onClose}>×</button>
      </header>
      {open ? children : null}
    </dialog>
  );
}

export function ErrorNote({ error }) {
  if (!error) return null;
  const text = typeof error === 'string' ? error : error.message;
  return <p class="error-note" role="alert">{text}{error.where ? <span class="where"> ({error.where})</span> : null}</p>;
}

export function Stat({ label, children, warn }) {
  return (
    <div class={warn ? 'stat warn' : 'stat'}>
      <dt>{label}</dt>
      <dd>{children}</dd>
    </div>
  );
}
