//! Frequency-domain system identification in the manner of CIFER.
