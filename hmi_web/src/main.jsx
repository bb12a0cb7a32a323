import { render } from 'preact';
import 'uplot/dist/uPlot.min.css';
import './styles.css';
import { App } from './app.jsx';

const root = document.getElementById('app');
root.textContent = ''; // the loading note
render(<App />, root);
