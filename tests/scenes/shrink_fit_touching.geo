// The rings of shrink_fit.geo drawn touching (delta = 0): the scene file prescribes the
// interference instead (interference = D on the pair).
delta = 0;
Include "shrink_fit.geo";
