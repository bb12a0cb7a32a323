// The shell: header, navigation (a menu button on a narrow screen), the
// connection state, who is logged in, and the page chosen by the URL's hash.
import { useEffect, useState } from 'preact/hooks';
import { logout, me } from './api/endpoints.js';
import { current, end, onSession } from './auth/session.js';
import { restart } from './live/hub.js';
import { useConnection, useLink } from './live/hooks.js';
import { LoginDialog } from './components/login.jsx';
import { OverviewPage } from './pages/overview.jsx';
import { TagsPage } from './pages/tags.jsx';
import { AxesPage } from './pages/axes.jsx';
import { MotionPage } from './pages/motion.jsx';
import { TrendsPage } from './pages/trends.jsx';
import { EventsPage } from './pages/events.jsx';
import { ProjectPage } from './pages/project.jsx';

export const PAGES = [
  { id: 'overview', label: 'Overview', component: OverviewPage },
  { id: 'tags', label: 'Tags & pins', component: TagsPage },
  { id: 'axes', label: 'Axes', component: AxesPage },
  { id: 'motion', label: 'Motion', component: MotionPage },
  { id: 'trends', label: 'Trends', component: TrendsPage },
  { id: 'events', label: 'Events', component: EventsPage },
  { id: 'project', label: 'Project', component: ProjectPage },
];

const pageFromHash = () => {
  const id = (location.hash || '').replace(/^#\/?/, '').split('?')[0];
  return PAGES.find((p) => p.id === id) || PAGES[0];
};

const CONNECTION_WORDS = {
  unknown: ['Connecting…', 'connecting'],
  online: ['Connected', 'live'],
  connecting: ['Connecting…', 'connecting'],
  live: ['Live', 'live'],
  paused: ['Paused (page hidden)', 'idle'],
  lost: ['Connection lost', 'lost'],
};

// What the page's values rest on: the live stream while one runs, else the
// requests the page polls with (overview, events, trends, project): every
// page says whether the PLC answers.
function linkState(stream, polled) {
  if (stream.state !== 'idle') return stream;
  return polled;
}

function ConnectionBadge({ c }) {
  const [text, cls] = CONNECTION_WORDS[c.state] || CONNECTION_WORDS.unknown;
  const title = c.state === 'lost'
    ? `${c.error || 'The PLC does not answer.'}${c.retryInMs ? ` Trying again in ${Math.ceil(c.retryInMs / 1000)} s.` : ''}`
    : text;
  return <span class={`conn conn-${cls}`} role="status" data-state={c.state} title={title}>{text}</span>;
}

export function App() {
  const [page, setPage] = useState(pageFromHash());
  const [menuOpen, setMenuOpen] = useState(false);
  const [session, setSession] = useState(current());
  const [loginOpen, setLoginOpen] = useState(false);
  const conn = linkState(useConnection(), useLink());

  useEffect(() => {
    const onHash = () => { setPage(pageFromHash()); setMenuOpen(false); };
    window.addEventListener('hashchange', onHash);
    return () => window.removeEventListener('hashchange', onHash);
  }, []);
  useEffect(() => onSession(setSession), []);
  // A session from before a reload of the page: still known to the PLC?
  // (A 401 ends it, through the http module.)
  useEffect(() => { if (current()) me().catch(() => {}); }, []);
  useEffect(() => { document.title = `${page.label} · syncplc`; }, [page]);

  async function doLogout() {
    try { await logout(); } catch { /* the token is dropped here whatever the server says */ }
    end();
    restart();
  }

  const Page = page.component;
  return (
    <div class="shell">
      <header class="topbar">
        <button type="button" class="btn-icon menu-button" aria-label="Menu" aria-expanded={menuOpen}
          onClick={() => setMenuOpen(!menuOpen)}>☰</button>
        <a class="brand" href="#/overview">syncplc</a>
        <nav class={menuOpen ? 'nav open' : 'nav'} aria-label="Pages">
          {PAGES.map((p) => (
            <a href={`#/${p.id}`} class={p.id === page.id ? 'active' : ''} aria-current={p.id === page.id ? 'page' : undefined}>{p.label}</a>
          ))}
        </nav>
        <ConnectionBadge c={conn} />
        <div class="who">
          {session ? (
            <>
              <span class="user" title={`Logged in as ${session.user} (${session.role})`}>
                <span class="user-name">{session.user}</span> <span class={`role role-${session.role}`}>{session.role}</span>
              </span>
              <button type="button" class="btn small" onClick={doLogout}>Log out</button>
            </>
          ) : (
            <button type="button" class="btn small primary" onClick={() => setLoginOpen(true)}>Log in</button>
          )}
        </div>
      </header>
      {conn.state === 'lost' ? (
        <div class="banner banner-lost" role="alert">
          Connection to the PLC lost: {conn.error || 'no answer'}. Values shown are the last received, greyed out. Trying again…
        </div>
      ) : null}
      <main class="page" id={`page-${page.id}`} data-link={conn.state === 'lost' ? 'lost' : 'ok'}>
        <Page session={session} onLogin={() => setLoginOpen(true)} />
      </main>
      <LoginDialog open={loginOpen} onClose={() => setLoginOpen(false)} />
    </div>
  );
}
